// layer_surface.hpp: the SH surface of one tissue layer (seed paper Sec. 2.1,
// Eq. 3): the closed boundary of a cylindrical disc, fitted with a parametric
// SH expansion of degree l, and the ray / projection queries the needle and
// the force mesh use (ContactSurface).
//
// Geometry (scene.hpp convention): the layer is the disc x^2 + y^2 <= R^2,
// bottom_z <= z <= top_z (bottom_z < top_z <= 0), axis = z axis. Its closed
// boundary (top face, side, bottom face) is genus 0.
//
// Parameterisation (the exact map LayerProfile::position, u -> boundary point),
// written in zeta = cos(theta) = u_z and the azimuth phi of u:
//   * north pole u = +z -> centre of the top face (the needle enters here);
//     south pole -> centre of the bottom face; x = rho cos(phi), y = rho sin(phi).
//   * top face, zeta in [zeta_t, 1]:   tau = (1 - zeta) / (1 - zeta_t),
//         rho = R sqrt(1 - (1 - tau)^k),  z = top_z
//   * side, zeta in [zeta_b, zeta_t]:  sigma = (zeta_t - zeta) / (zeta_t - zeta_b),
//         rho = R,  z = top_z - H S_k(sigma)   (H = top_z - bottom_z)
//   * bottom face, zeta in [-1, zeta_b]: tau = (1 + zeta) / (1 + zeta_b),
//         rho = R sqrt(1 - (1 - tau)^k),  z = bottom_z
//   with S_k the smooth step whose first k - 1 derivatives vanish at both ends
//   (regularised incomplete beta I_sigma(k, k), a polynomial). Why this form:
//   the SH of order m are polynomials in zeta times (x + iy)^m, so the map is
//   smooth on the sphere when z(zeta) and rho / sin(theta) are smooth in zeta;
//   rho^2 / sin^2(theta) = R^2 (1 - (1 - tau)^k) / ((1 - zeta)(1 + zeta)) is a
//   polynomial / (1 + zeta) near the north pole (rho is odd in theta there, the
//   map is regular at the pole with non-zero speed), and the speed along the
//   profile vanishes to order k - 1 at the rim corners, so the map is C^(k-1)
//   across them. Only orders m = 0 (z) and m = +-1 (x, y) are present: the
//   fit's higher orders (rounding level, checked) are set to zero so queries
//   cost O(l) rather than O(l^2).
//
// Fit: least squares on a Gauss-Legendre(zeta) x uniform(phi) grid with more
// samples than unknowns (fit_sh_on_grid).
//
// Errors reported by the fit: the top face against the exact plane z = top_z
// within lateral radius 0.9 R (vertical distance of the fitted point, sampled
// uniformly in area), and the parametric error |X_fit(u) - X_exact(u)| over
// the whole sphere (area-weighted rms).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "puncture/contact_surface.hpp"
#include "puncture/sh/sh_fit.hpp"
#include "puncture/sh/sh_surface.hpp"

namespace puncture {

/// Shape of the parameterisation and of the fitting grid. Defaults chosen by a
/// small study of the top-face error (relative to the thickness H, which it
/// is proportional to) at l = 16 and 32 over zeta_t in [0.1, 0.4], zeta_b in
/// [-0.8, -0.3], k in 3..6: with these, max |z - top_z| / H over 0.9 R is
/// 4e-2, 7e-3, 3e-4, 1e-4, 3e-5 at l = 4, 8, 16, 24, 32.
struct LayerFitOptions {
  double top_rim_cos_theta = 0.3;      ///< zeta_t: cos(theta) of the top rim (> 0: the gnomonic chart covers the face)
  double bottom_rim_cos_theta = -0.5;  ///< zeta_b: cos(theta) of the bottom rim (< zeta_t)
  int corner_order = 4;                ///< k: profile speed vanishes to order k - 1 at the rims (C^(k-1) map)
  double oversampling = 2.0;           ///< polar nodes = ceil(oversampling (l + 1)); azimuths = 2 l + 2
};

/// The exact map from the unit sphere onto the disc boundary (see header comment).
struct LayerProfile {
  double top_z_m = 0.0;
  double bottom_z_m = -1e-3;
  double radius_m = 0.03;
  LayerFitOptions options;

  double thickness_m() const { return top_z_m - bottom_z_m; }
  /// Lateral radius rho (m) and height z (m) of the profile at zeta = cos(theta).
  void profile(double zeta, double& rho_m, double& z_m) const;
  /// Exact boundary point for direction u (normalised on entry).
  Eigen::Vector3d position(const Eigen::Vector3d& u) const;
  /// Unit direction on the top face whose exact point lies at lateral
  /// position (x, y) (clamped to the rim if outside the disc).
  Eigen::Vector3d top_face_direction(double x_m, double y_m) const;
};

class LayerSurface final : public ContactSurface {
 public:
  /// Fit the boundary of the disc bottom_z < z < top_z <= 0, radius R, at SH
  /// degree l >= 2. Throws std::invalid_argument on bad geometry.
  static LayerSurface fit(double top_z_m, double bottom_z_m, double radius_m, int degree,
                          const LayerFitOptions& options = {});

  const SHFitReport& fit_report() const { return report_; }
  const LayerProfile& profile() const { return profile_; }
  const ParametricSHSurface& surface() const { return surface_; }
  int degree() const { return surface_.degree(); }

  /// Top face against the exact plane z = top_z within radius 0.9 R (m).
  double top_face_max_error_m() const { return top_face_max_error_m_; }
  double top_face_rms_error_m() const { return top_face_rms_error_m_; }
  /// Area-weighted rms of |X_fit(u) - X_exact(u)| over the sphere (m).
  double whole_surface_rms_error_m() const { return whole_surface_rms_error_m_; }

  /// First crossing of origin + s * direction (s >= 0) with the TOP face (the
  /// needle comes from above; crossings of the side or bottom are not
  /// reported). Newton in the gnomonic chart u = (a, b, 1) / |(a, b, 1)|
  /// about the north pole (regular at the pole), warm-started from the exact
  /// plane hit mapped through LayerProfile::top_face_direction; converges in
  /// 2-3 iterations. Returns false for a ray parallel to the face, a miss
  /// (outside the rim), s < 0 or no convergence in 12 iterations.
  /// Does not allocate: it uses a scratch workspace owned by the object, so a
  /// LayerSurface must not be queried from several threads at once.
  bool intersect_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double& s,
                     SurfacePoint& hit) const override;

  /// Foot of the perpendicular from p onto the top face (Gauss-Newton in the
  /// gnomonic chart, started above p). For points above/below the face.
  SurfacePoint project(const Eigen::Vector3d& p) const override;

  /// Fitted position (m) and position + unit outward normal at direction u.
  Eigen::Vector3d position(const Eigen::Vector3d& u) const;
  SurfacePoint evaluate(const Eigen::Vector3d& u) const;

  /// Parameter point (unit direction) of the top face whose FITTED position
  /// lies at lateral position (x, y) (m): used to place force-mesh nodes.
  /// Throws std::runtime_error if Newton does not converge.
  Eigen::Vector3d top_face_parameter(double x_m, double y_m) const;

  /// Closed triangulation for output (VTK): n_theta >= 2 bands in theta,
  /// n_phi >= 3 azimuths; vertices (2 + (n_theta - 1) n_phi) x 3 in m,
  /// triangles 2 n_phi (n_theta - 1) x 3, counter-clockwise seen from outside.
  void tessellate(int n_theta, int n_phi, Eigen::MatrixX3d& vertices,
                  Eigen::MatrixX3i& triangles) const;

 private:
  LayerSurface(LayerProfile profile, ParametricSHSurface surface, SHFitReport report);
  void measure_errors();
  /// u(a, b) on the gnomonic chart and its partial derivatives.
  static void gnomonic(double a, double b, Eigen::Vector3d& u, Eigen::Vector3d& du_da,
                       Eigen::Vector3d& du_db);

  LayerProfile profile_;
  ParametricSHSurface surface_;
  SHFitReport report_;
  double top_face_max_error_m_ = 0.0;
  double top_face_rms_error_m_ = 0.0;
  double whole_surface_rms_error_m_ = 0.0;
  mutable SHWorkspace workspace_;  ///< scratch for the allocation-free queries (not thread-safe)
};

/// Fit error of a layer surface for each degree: the "accuracy costs time" table.
struct LayerFitErrorRow {
  int degree = 0;
  double top_face_max_error_m = 0.0;
  double top_face_rms_error_m = 0.0;
  double whole_surface_rms_error_m = 0.0;
  double condition_number = 0.0;
};
std::vector<LayerFitErrorRow> layer_fit_error_sweep(double top_z_m, double bottom_z_m, double radius_m,
                                                    const std::vector<int>& degrees,
                                                    const LayerFitOptions& options = {});

}  // namespace puncture
