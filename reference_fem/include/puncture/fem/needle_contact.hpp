// needle_contact.hpp: the rigid needle of the axisymmetric FEM reference and
// its frictional contact with the tissue (header-only, no deal.II).
//
// Geometry, in the meridian plane (r >= 0 from the needle axis, z up; the
// needle moves along the axis; z_tip = height of its cutting edge):
//   the cutting edge is the circle r = r_c at z = z_tip; the tip flank is the
//   cone through the edge at angle beta to the axis, rising to the shaft
//   radius a at z_tip + (a - r_c) / tan(beta); the shaft r = a above it.
//   Friction acts on the shaft only: the flank is the cutting bevel.
//   Tissue OUTSIDE the crack (outer side) meets the needle body
//     { r < a and z > z_tip + (r - r_c) / tan(beta) }
//   (the flank continued inward as a cone, a smooth stand-in for the sharp
//   edge); tissue INSIDE the crack (core side) meets only the inner wall
//   r = r_c above the edge (the lumen of a hollow needle; for a bevel, the
//   material the slit would not displace).
// Contact is a node-to-rigid-surface penalty: a node at x inside the body,
// penetration p = -g (g = signed distance to the nearest face), gets the force
// N(p) n along the face's outward normal n, with the C1 penalty law
//   N(p) = k_n p^2 / (2 eps) for p < eps,  k_n (p - eps / 2) beyond
// (ContactPenalty), so a node entering contact does not see a jump in
// stiffness. The inner wall acts on core-side nodes only above the edge,
// switched on by a smooth ramp over a height h_edge above the edge (the edge
// is rounded), which keeps the energy C1 as the edge passes a node. Friction
// (shaft side only) is Coulomb with a static and a dynamic coefficient,
// regularised by a tangential penalty k_t: the stick point is remembered in
// the needle's frame, the elastic slip xi = (x - x_edge - anchor) . t gives
// the force -mu N tanh(k_t xi / (mu N)) t (stick for small slips, slide at
// mu N for large ones, smooth in between so Newton converges through
// stick-slip and through the reversal at withdrawal); plastic slip is
// committed between steps (see nodal_contact).
//
// Units: m, N, N/m.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace puncture::fem {

using Vec2 = std::array<double, 2>;  ///< (r, z)

inline double dot(const Vec2& a, const Vec2& b) { return a[0] * b[0] + a[1] * b[1]; }

/// C1 penalty law: energy, force and stiffness of a penetration p (m).
struct ContactPenalty {
  double k_N_per_m = 0.0;  ///< stiffness beyond the rounding
  double rounding_m = 0.0; ///< eps: quadratic onset below this penetration
  double force(double p) const {
    if (p <= 0.0) return 0.0;
    return p < rounding_m ? 0.5 * k_N_per_m * p * p / rounding_m : k_N_per_m * (p - 0.5 * rounding_m);
  }
  double stiffness(double p) const {
    if (p <= 0.0) return 0.0;
    return p < rounding_m ? k_N_per_m * p / rounding_m : k_N_per_m;
  }
  double energy(double p) const {
    if (p <= 0.0) return 0.0;
    const double e = rounding_m;
    return p < e ? k_N_per_m * p * p * p / (6.0 * e) : k_N_per_m * (0.5 * p * p - 0.5 * e * p + e * e / 6.0);
  }
};

/// Axisymmetric rigid needle: cutting edge radius r_c, shaft radius a, flank angle beta.
struct RigidNeedle {
  double edge_radius_m = 0.4e-3;    ///< r_c
  double shaft_radius_m = 0.635e-3; ///< a >= r_c
  double flank_angle_rad = 0.35;    ///< beta, between flank and axis (0, pi/2)
  double z_tip_m = 0.0;             ///< current height of the cutting edge

  void check() const {
    if (!(edge_radius_m > 0.0 && shaft_radius_m >= edge_radius_m))
      throw std::invalid_argument("needle: need 0 < edge radius <= shaft radius");
    if (!(flank_angle_rad > 0.0 && flank_angle_rad < 1.5))
      throw std::invalid_argument("needle: flank angle must lie in (0, 1.5) rad");
  }
  /// Height of the flank cone above the edge at radius r (negative inside r_c).
  double flank_height(double r) const { return (r - edge_radius_m) / std::tan(flank_angle_rad); }
  /// Height (z) where the flank meets the shaft.
  double shoulder_z() const { return z_tip_m + flank_height(shaft_radius_m); }
};

/// Where a node touches the needle: penetration depth (m, >= 0; 0 = no
/// contact), the outward unit normal n of the touched face, its unit tangent
/// t (pointing up the needle) and whether the face is the shaft or flank
/// (frictional) or the inner wall.
struct ContactPoint {
  double penetration_m = 0.0;
  Vec2 normal{1.0, 0.0};
  Vec2 tangent{0.0, 1.0};
  bool frictional = false;
  /// Share of Coulomb friction in [0, 1]: 0 on the flank (the cutting bevel),
  /// 1 on the shaft, a smooth step over the rounded shoulder (so a node sliding
  /// round the shoulder sees no jump), and its gradient (1/m).
  double friction_weight = 0.0;
  Vec2 dfriction_weight_dx{0.0, 0.0};
  /// Curvature of the touched face (1/m): 1/d on the rounded shoulder, where
  /// the normal turns with the node (dn/dx = curvature (I - n n)), 0 on the
  /// flat flank and shaft. Enters the consistent tangent of the contact force.
  double curvature_per_m = 0.0;
};

/// Contact of a tissue node at x = (r, z) on the outer side of the crack,
/// with the shoulder (flank meets shaft) rounded by the radius `rounding_m`:
/// the body is the convex set {(x - edge) . n_flank < 0, r < a}; its distance
/// is taken from the body shrunk by the rounding (exact distance to a convex
/// polygon: a face, or its corner), minus the rounding. The normal is then
/// continuous wherever the penetration is below the rounding.
inline ContactPoint outer_contact(const RigidNeedle& needle, const Vec2& x, double rounding_m = 0.0) {
  ContactPoint c;
  const double beta = needle.flank_angle_rad;
  const double rho = rounding_m;
  const Vec2 n1{std::cos(beta), -std::sin(beta)}, n2{1.0, 0.0};
  const Vec2 t1{std::sin(beta), std::cos(beta)};
  const Vec2 from_edge{x[0] - needle.edge_radius_m, x[1] - needle.z_tip_m};
  const double g1 = dot(from_edge, n1) + rho;           // flank of the shrunk body
  const double g2 = x[0] - needle.shaft_radius_m + rho;  // shaft of the shrunk body
  // Corner of the shrunk body: on both shrunk lines.
  const double r_corner = needle.shaft_radius_m - rho;
  // Point on shrunk flank line at r = r_corner: (from_edge . n1 = -rho).
  const double z_corner = needle.z_tip_m + (r_corner - needle.edge_radius_m - (-rho) * n1[0]) / t1[0] * t1[1] + (-rho) * n1[1];
  double d = 0.0;
  Vec2 n = n1;
  bool on_corner = false;
  if (g1 <= 0.0 && g2 <= 0.0) {  // inside the shrunk body (penetration beyond the rounding)
    d = std::max(g1, g2);
    n = g1 >= g2 ? n1 : n2;
  } else {
    // Projections onto the two shrunk faces, kept if they stay on the face.
    const Vec2 p1{x[0] - g1 * n1[0], x[1] - g1 * n1[1]};
    const Vec2 p2{x[0] - g2, x[1]};
    const bool on_face1 = g1 > 0.0 && p1[0] <= r_corner + 1e-15;
    const bool on_face2 = g2 > 0.0 && p2[1] >= z_corner - 1e-15;
    if (on_face1 && (!on_face2 || g1 <= g2)) {
      d = g1;
      n = n1;
    } else if (on_face2) {
      d = g2;
      n = n2;
    } else {
      const Vec2 v{x[0] - r_corner, x[1] - z_corner};
      d = std::sqrt(dot(v, v));
      n = d > 0.0 ? Vec2{v[0] / d, v[1] / d} : n1;
      on_corner = d > 0.0;
    }
  }
  const double penetration = rho - d;
  if (!(penetration > 0.0)) return c;
  c.penetration_m = penetration;
  c.normal = n;
  c.tangent = {-n[1], n[0]};
  // Friction acts on the shaft, fading out over the rounded shoulder; the
  // tip's flank is the cutting bevel, whose force is its normal pressure.
  // w = smoothstep(s), s = (n_r - cos beta) / (1 - cos beta).
  const double span = 1.0 - std::cos(beta);
  const double s = span > 0.0 ? std::clamp((n[0] - std::cos(beta)) / span, 0.0, 1.0) : 1.0;
  c.friction_weight = s * s * (3.0 - 2.0 * s);
  if (on_corner) c.curvature_per_m = 1.0 / d;
  if (on_corner && s > 0.0 && s < 1.0) {
    // d n_r / dx = (e_r - n_r n) / d on the rounded corner (n = v / |v|).
    const double dw_ds = 6.0 * s * (1.0 - s) / span;
    const double d_inv = 1.0 / d;
    c.dfriction_weight_dx = {dw_ds * (1.0 - n[0] * n[0]) * d_inv, dw_ds * (-n[0] * n[1]) * d_inv};
  }
  c.frictional = c.friction_weight > 0.0;
  return c;
}

/// Friction state of one node (committed at converged steps).
struct FrictionHistory {
  bool in_contact = false;
  bool sliding = false;
  Vec2 anchor{0.0, 0.0};  ///< stick point relative to the cutting edge (needle frame), m
};

struct FrictionCoefficients {
  double dynamic = 0.0;  ///< mu_d
  double static_ = 0.0;  ///< mu_s >= mu_d
};

/// Force on a tissue node (N) from the needle and its derivative with respect
/// to the node's position (N/m, 2x2, not symmetric when sliding), with the
/// trial friction history.
struct NodalContactResponse {
  Vec2 normal_force{0.0, 0.0};
  Vec2 friction_force{0.0, 0.0};
  std::array<std::array<double, 2>, 2> dforce_dx{};  ///< d(normal + friction) / dx
  FrictionHistory history;
};

/// Contact of a core-side node with the inner wall r = r_c: the energy
/// s(z) E(r - r_c) with the C1 penalty energy E and a smooth step s from 0 at
/// the edge (z = z_tip) to 1 at z_tip + h_edge (a rounded edge), so a node the
/// edge passes is pushed in gradually. h_edge <= 0: s = 1 at every height (the
/// wall continued below the edge as a guide that holds the crack line at
/// r <= r_c; see reference_fem/README.md). Frictionless (the lumen).
inline NodalContactResponse core_wall_contact(const RigidNeedle& needle, const Vec2& x,
                                              const ContactPenalty& penalty, double h_edge) {
  NodalContactResponse out;
  const double p = x[0] - needle.edge_radius_m;
  if (p <= 0.0) return out;
  double s = 1.0, ds = 0.0, d2s = 0.0;
  const double t = h_edge > 0.0 ? (x[1] - needle.z_tip_m) / h_edge : 1.0;
  if (t <= 0.0) return out;
  if (t < 1.0) {  // smoothstep 3t^2 - 2t^3
    s = t * t * (3.0 - 2.0 * t);
    ds = 6.0 * t * (1.0 - t) / h_edge;
    d2s = (6.0 - 12.0 * t) / (h_edge * h_edge);
  }
  const double F = penalty.force(p), K = penalty.stiffness(p), E = penalty.energy(p);
  // force = -grad(s E): (-s F, -ds E); derivative = -Hessian.
  out.normal_force = {-s * F, -ds * E};
  out.dforce_dx[0][0] = -s * K;
  out.dforce_dx[0][1] = out.dforce_dx[1][0] = -ds * F;
  out.dforce_dx[1][1] = -d2s * E;
  out.history.in_contact = true;
  return out;
}

/// Elastic slip (in units of mu N / k_t) a sliding node keeps from one step to
/// the next: tanh(2) = 0.96, so a node that slides starts its next step at 96 %
/// of the Coulomb force.
inline constexpr double kCommittedSlipRatio = 2.0;

/// Penalty contact and friction of an outer-side node touching the face c.
/// edge = (r_c, z_tip): position of the cutting edge; k_t: tangential penalty (N/m);
/// min_slip_m: the elastic slip over which the friction builds up to mu N is
/// at least this (m): k_t is capped at mu N / min_slip_m. Without the floor,
/// the slip range mu N / k_t (a few times mu x the penetration) shrinks to
/// nanometres where the contact pressure is small, the friction becomes a
/// step at that scale, and Newton cannot tell a sticking node from a sliding
/// one (it cycles, or its steps go uphill at any length it can try).
inline NodalContactResponse nodal_contact(const ContactPoint& c, const Vec2& x, const Vec2& edge,
                                          const FrictionHistory& committed, const FrictionCoefficients& mu,
                                          const ContactPenalty& penalty, double k_t, double min_slip_m = 0.0) {
  NodalContactResponse out;
  if (!(c.penetration_m > 0.0)) return out;  // no contact: friction history reset
  const double N = penalty.force(c.penetration_m), dN = penalty.stiffness(c.penetration_m);
  // dn/dx = kappa (I - n n) on the rounded shoulder (0 on a flat face); the
  // tangent t = (-n_z, n_r) turns with it: dt/dx = (-dn_z/dx, dn_r/dx).
  const double kappa = c.curvature_per_m;
  std::array<std::array<double, 2>, 2> dn{}, dt{};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) dn[i][j] = kappa * ((i == j ? 1.0 : 0.0) - c.normal[i] * c.normal[j]);
  for (int j = 0; j < 2; ++j) {
    dt[0][j] = -dn[1][j];
    dt[1][j] = dn[0][j];
  }
  for (int i = 0; i < 2; ++i) {
    out.normal_force[i] = N * c.normal[i];
    for (int j = 0; j < 2; ++j) out.dforce_dx[i][j] = -dN * c.normal[i] * c.normal[j] + N * dn[i][j];
  }
  out.history.in_contact = true;
  const Vec2 rel{x[0] - edge[0], x[1] - edge[1]};
  out.history.anchor = rel;
  if (!c.frictional || mu.dynamic <= 0.0) return out;
  // A node that touches for the first time carries no friction in this step;
  // it sticks where it is when the step converges (the anchor above).
  if (!committed.in_contact) return out;
  const Vec2 anchor = committed.anchor;
  const Vec2 slip{rel[0] - anchor[0], rel[1] - anchor[1]};
  const double xi = dot(slip, c.tangent);
  // Regularised Coulomb friction, smooth within a step so that Newton sees no
  // switch: f = -mu N tanh(k_t xi / (mu N)) along t. Small slips stick
  // elastically (f = -k_t xi), large ones slide at mu N. Plastic slip is
  // committed between steps: a node whose elastic slip exceeds
  // kCommittedSlipRatio mu N / k_t keeps that much and moves its stick
  // point. A node that stuck in the last step resists with mu_s, a sliding one
  // with mu_d (the drop from static to dynamic happens between steps).
  const double mu_now = committed.sliding ? mu.dynamic : mu.static_;
  const double cap = mu_now * N;
  if (!(cap > 0.0)) return out;
  // The slip length of the regularisation: cap / k_t, at least min_slip_m
  // (then u = xi / min_slip_m no longer depends on N).
  const bool floored = min_slip_m > 0.0 && cap < k_t * min_slip_m;
  const double slip_length = floored ? min_slip_m : cap / k_t;
  const double u = xi / slip_length;
  const double th = std::tanh(u), sech2 = 1.0 - th * th;
  const double f = -cap * th;
  const double df_dxi = -cap / slip_length * sech2;
  const double df_dN = floored ? -mu_now * th : -mu_now * (th - u * sech2);
  // d xi / dx = t + slip . dt/dx; d N / dx = dN (-n) (the penetration falls
  // along n); the force w f t also turns with t on the shoulder.
  const double w = c.friction_weight;
  for (int i = 0; i < 2; ++i) {
    out.friction_force[i] = w * f * c.tangent[i];
    for (int j = 0; j < 2; ++j) {
      const double dxi_dx = c.tangent[j] + slip[0] * dt[0][j] + slip[1] * dt[1][j];
      out.dforce_dx[i][j] += c.tangent[i] * (w * (df_dxi * dxi_dx - df_dN * dN * c.normal[j]) +
                                             f * c.dfriction_weight_dx[j]) +
                             w * f * dt[i][j];
    }
  }
  const double xi_max = kCommittedSlipRatio * slip_length;
  if (std::abs(xi) > xi_max) {
    out.history.sliding = true;
    const double xi_e = xi > 0.0 ? xi_max : -xi_max;
    for (int i = 0; i < 2; ++i) out.history.anchor[i] = rel[i] - xi_e * c.tangent[i];
  } else {
    out.history.sliding = false;
    out.history.anchor = anchor;
  }
  return out;
}

}  // namespace puncture::fem
