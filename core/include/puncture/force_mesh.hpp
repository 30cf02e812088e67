// force_mesh.hpp: the mass-spring force mesh of one layer surface (seed paper
// Sec. 2.2, Fig. 1-2, Eq. 5).
//
// Geometry. A hexagonal ring lattice (hex_lattice.hpp) of w rings and spacing
// L is laid out in the tangent plane of the contact point and every node is
// placed on the layer surface with ContactSurface::project, which also gives
// the node's outward unit normal n_i. Node 0 is the contact node (ring 1).
//
// Mechanics (our reading of Fig. 2; the paper gives only Eq. 5):
//   * every node i moves along its own normal with the scalar deflection
//     z_i (m, the paper's Delta Z, positive INTO the tissue), so its position
//     is  x_i = x_i^0 - z_i n_i;
//   * every node carries a virtual spring of stiffness K (N/m) along the
//     normal, anchored at the rest position: force -K z_i;
//   * every surface spring (neighbours i, j) acts as a membrane spring of
//     transverse stiffness k_s (N/m, ForceMeshParams::surface_stiffness_N_per_m)
//     between the deflections: force on i is -k_s (z_i - z_j);
//   * node mass m = density * layer thickness * sqrt(3)/2 L^2 (the tissue
//     column under one hexagon cell), node damping c (N s/m) on z_i';
//   * the outer ring is free (no anchor other than its virtual springs);
//   * the contact node's deflection z_0 is prescribed by the needle.
// So for the free nodes f:  m z_f'' + c z_f' + K_ff z_f = b z_0, with
// K_ff = K I + k_s (graph Laplacian restricted to f) and b_i = k_s for the
// neighbours of the contact node. The deflection of the rings comes out of
// this system, not from a fall-off curve.
//
// Stiffening in the mesh (optional; ForceMeshParams::nonlinear()). The
// springs may stiffen with their own deformation:
//   virtual spring:  f_v(z) = K z (1 + (z / z_v)^2)                 (z_v = virtual_stiffening_m)
//   surface spring:  f_s(delta) = k_s delta + k_a (s - L) delta / s,  s = sqrt(L^2 + delta^2)
// f_s is the transverse force of the linear membrane spring plus that of an
// axial spring of stiffness k_a (surface_axial_stiffness_N_per_m) between two
// nodes L apart in the plane and delta apart along the normal (exact
// geometry; ~ k_a delta^3 / (2 L^2) at small slopes): a steep tent stretches
// its springs, which spreads the load outwards, so the tent widens with depth
// as a tissue surface does. Both laws are odd, convex in energy and strictly
// increasing, so the tangent stays symmetric positive definite. The step is
// then solved by Newton's method with a backtracking line search on the
// residual (tangent refactorised on its fixed sparse pattern, no allocation).
// It is solved on the lattice's cells (core/src/lattice_cells.hpp: the orbits
// of its six-fold symmetry, 20 cells for w = 8 instead of 168 free nodes):
// every node is alike and the needle loads node 0 only, so a state constant
// on the cells stays so (the mesh starts at rest and is reset to rest when
// laid out again), and each cell's equation is that of every node in it;
// the explicit integrator does such a mesh implicitly (explicit_falls_back_to_implicit()).
// With linear springs every formula below is the paper's.
//
// Forces. The surface force on the needle is the elastic reaction at the
// contact node, F = K z_0 + k_s sum_{j ~ 0} (z_0 - z_j) (N, positive when it
// resists insertion; the contact node's own inertia and damping are carried
// by the needle and not included). At equilibrium it equals Eq. (5):
// F = K dZ_1 + K sum_{j=2..w} 6 (j-1) dZ_j with dZ_j the mean deflection of
// ring j (global force balance: the Laplacian terms sum to zero). With
// stiffening virtual springs Eq. (5) sums each spring's own force,
// F = sum_i f_v(z_i), which the same balance makes equal to the reaction
// (the surface springs are internal and odd in delta).
//
// Breakthrough. Ring j counts as deformed when its mean deflection exceeds
// ForceMeshParams::deformed_threshold_m. deformed_rings() is the largest j
// whose ring (and all rings inside it) is deformed; when it reaches w the
// layer breaks (Table 1 post-puncture).
//
// Contact point. The mesh is laid out at the contact point it is given and
// along the surface normal there; relayout() lays it again at another point
// (e.g. where an off-axis needle actually touches the surface) without
// allocating: the matrices depend only on the lattice, K, k_s, mass and dt,
// not on where the lattice lies.
//
// Split step. Every integrator's step is affine in the contact deflection z0
// prescribed at the end of the step: predict() integrates the free nodes with
// z0 = 0 at the end of the step, and commit(z0) adds z0 times the unit
// response (precomputed at construction). A stiffening mesh's step is not
// affine: predict() solves it for the contact deflection of the last commit
// z0* and linearises it there (the sensitivity dz/dz0 from the converged
// tangent), commit(z0) takes the linearised state at z0; the error is of
// order (z0 - z0*)^2, one tick of needle travel squared, and the next
// predict() solves the true step again. In between, predicted_reaction_N(z0)
// = intercept + slope z0 is the contact reaction the step would give, so a
// caller can choose z0 from a force balance (layers in series, see
// simulator.hpp) before committing. advance(z0) = predict(); commit(z0).
//
// Time integration (one fixed step dt per advance(), the haptic step):
//   QuasiStatic: equilibrium every step, z = u z_0 with the unit-deflection
//       influence vector u precomputed at construction (O(N) per step).
//   Explicit:    symplectic Euler (v += dt a; z += dt v) with the damping
//       evaluated explicitly. A mode omega is stable for
//       omega dt < 2 (sqrt(1 + zeta^2) - zeta), zeta = c / (2 m omega), i.e.
//       omega^2 dt^2 + 2 (c/m) dt < 4, and dt < 2 m / c (Jury conditions of
//       the 2 x 2 step matrix); dt_crit is that limit for omega_max. omega_max^2 <= max_i (K + 2 k_s deg_i) / m is the
//       Gershgorin bound on the eigenvalues of M^-1 K_ff, so dt_crit is safe.
//       When dt > safety * dt_crit the step is split into substeps (the
//       contact deflection is interpolated linearly across them); if more
//       than max_explicit_substeps would be needed the step is done with the
//       implicit integrator instead.
//   Implicit:    backward Euler; the sparse LDLT of (M/dt^2 + C/dt + K_ff) is
//       factorised once at construction (contact node eliminated as a
//       prescribed value), on the lattice's cells as the stiffening mesh's
//       step (the state stays constant on them); each step is two triangular
//       solves on preallocated storage (no allocation).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "puncture/contact_surface.hpp"
#include "puncture/hex_lattice.hpp"
#include "puncture/scene.hpp"

namespace puncture {

namespace detail {
class FixedPatternLdlt;
/// Owns the tangent's factorisation of a stiffening mesh and copies it
/// deeply, so that ForceMesh keeps its value semantics.
class TangentFactorization {
 public:
  TangentFactorization();
  ~TangentFactorization();
  TangentFactorization(const TangentFactorization& other);
  TangentFactorization& operator=(const TangentFactorization& other);
  TangentFactorization(TangentFactorization&&) noexcept;
  TangentFactorization& operator=(TangentFactorization&&) noexcept;
  void create();
  FixedPatternLdlt* operator->() const { return ldlt_.get(); }

 private:
  std::unique_ptr<FixedPatternLdlt> ldlt_;
};
}  // namespace detail

// --- the springs' laws (N, N/m, J; deflections in m), see the header ---
double virtual_spring_force_N(const ForceMeshParams& p, double deflection_m);
double virtual_spring_stiffness_N_per_m(const ForceMeshParams& p, double deflection_m);
double virtual_spring_energy_J(const ForceMeshParams& p, double deflection_m);
/// Transverse force of one surface spring whose ends differ in deflection by delta_m.
double surface_spring_force_N(const ForceMeshParams& p, double delta_m);
double surface_spring_stiffness_N_per_m(const ForceMeshParams& p, double delta_m);
double surface_spring_energy_J(const ForceMeshParams& p, double delta_m);

enum class MeshIntegrator { QuasiStatic, Explicit, Implicit };

/// "quasi_static", "explicit" or "implicit" (RealtimeSettings::integrator);
/// throws std::invalid_argument naming realtime.integrator otherwise.
MeshIntegrator parse_mesh_integrator(const std::string& name);
const char* to_string(MeshIntegrator integrator);

/// Numerical knobs of the force-mesh time integration.
struct MeshIntegrationSettings {
  MeshIntegrator integrator = MeshIntegrator::Implicit;
  double time_step_s = 1e-3;          ///< fixed step of advance() (the haptic step)
  double explicit_safety = 0.9;       ///< explicit substep <= safety * dt_crit
  int max_explicit_substeps = 64;     ///< beyond this the explicit step falls back to implicit
};

class ForceMesh {
 public:
  /// contact: the contact point and outward normal on `surface` (m).
  /// layer_thickness_m, density_kg_per_m3: give the node mass.
  /// Throws std::invalid_argument on non-positive parameters or a projection
  /// that returns non-finite positions.
  ForceMesh(const ContactSurface& surface, const SurfacePoint& contact, const ForceMeshParams& params,
            double layer_thickness_m, double density_kg_per_m3, const MeshIntegrationSettings& settings);

  /// Advances one step dt with the contact-node deflection prescribed
  /// (m, into the tissue; negative values are clamped to 0). No allocation.
  /// A stiffening mesh solves this step at the prescribed deflection (no
  /// linearisation: predict() + commit() are the split form the layer chain uses).
  /// Throws std::runtime_error if the state becomes non-finite.
  void advance(double contact_deflection_m);
  /// First half of advance(): the step with zero contact deflection at its
  /// end (scratch state; the mesh is unchanged until commit). No allocation.
  void predict();
  /// Contact reaction (N) the predicted step gives for contact deflection z0 (m).
  double predicted_reaction_N(double contact_deflection_m) const {
    return predicted_intercept_N_ + reaction_slope_N_per_m_ * contact_deflection_m;
  }
  /// d(reaction)/d(z0) of one step (N/m): the static stiffness for the
  /// quasi-static integrator, the stiffer dynamic one otherwise.
  double reaction_slope_N_per_m() const { return reaction_slope_N_per_m_; }
  /// Second half of advance(): the predicted step with contact deflection z0
  /// (m, negative values are clamped to 0). Throws std::runtime_error if the
  /// state becomes non-finite.
  void commit(double contact_deflection_m);
  /// Back to the undeformed state at rest.
  void reset();
  /// Lays the mesh out again at `contact` on `surface` (at rest), at once in
  /// the tangent plane of the contact point with the contact normal at every
  /// node (exact for a flat surface); the projections of the nodes onto the
  /// surface follow in refine_layout(). The mechanics do not depend on the
  /// node positions (scalar deflections along the normals), so the force is
  /// exact from the first tick; only the drawn surface is refined. No
  /// allocation (ContactSurface::project must not allocate).
  void relayout(const ContactSurface& surface, const SurfacePoint& contact);
  /// Projects up to max_nodes pending nodes onto the surface (a few us each
  /// on an SH surface: the simulator spreads them over ticks). Returns the
  /// number still pending. Throws std::invalid_argument if a projection is
  /// not finite. `surface` must be the one given to relayout().
  int refine_layout(int max_nodes);
  bool layout_pending() const { return next_projection_ < lattice_.node_count(); }
  int pending_nodes() const { return lattice_.node_count() - next_projection_; }
  /// True if the mesh is laid out at `contact` (position within tolerance_m,
  /// normal within 1e-9).
  bool laid_at(const SurfacePoint& contact, double tolerance_m) const;

  // --- forces (N, positive resisting insertion) ---
  double contact_reaction_N() const;  ///< elastic reaction at the contact node
  double eq5_force_N() const;         ///< K dZ_1 + K sum_j 6 (j-1) dZ_j (Eq. 5)
  /// Reaction per unit contact deflection at equilibrium, N/m (at small
  /// deflection for a stiffening mesh).
  double static_stiffness_N_per_m() const { return static_stiffness_N_per_m_; }
  /// Newton iterations of the last predicted step (0 for a linear mesh).
  int last_newton_iterations() const { return newton_iterations_; }

  // --- deformation ---
  int rings() const { return params_.rings_w; }
  int node_count() const { return lattice_.node_count(); }
  double ring_mean_deflection_m(int ring) const {  ///< ring in 1..w
    update_ring_means();
    return ring_mean_m_[ring - 1];
  }
  int deformed_rings() const;
  /// True when every node's deflection is below tolerance_m and its speed
  /// below tolerance_m per time step (nothing left to integrate).
  bool at_rest(double tolerance_m = 1e-15) const {
    return max_abs_deflection_m_ <= tolerance_m && max_abs_velocity_m_per_s_ * settings_.time_step_s <= tolerance_m;
  }
  bool broken() const { return deformed_rings() >= params_.rings_w; }
  const Eigen::VectorXd& deflections_m() const {  ///< size N, [0] = contact node
    update_nodes();
    return z_;
  }
  const Eigen::VectorXd& velocities_m_per_s() const {  ///< size N, [0] = contact node rate
    update_nodes();
    return v_;
  }
  /// Equilibrium deflection of every node per metre of contact deflection (u_0 = 1).
  const Eigen::VectorXd& unit_influence() const { return influence_; }

  // --- geometry (3 x N, m) ---
  const Eigen::Matrix3Xd& rest_positions() const { return rest_; }
  const Eigen::Matrix3Xd& normals() const { return normals_; }
  /// rest - z normals, computed when asked after a step (the haptic tick does not need it).
  const Eigen::Matrix3Xd& positions() const;
  const HexLattice& lattice() const { return lattice_; }
  const std::vector<int>& node_rings() const { return lattice_.ring; }

  // --- energy (J) ---
  double kinetic_energy_J() const;
  double virtual_spring_energy_J() const;
  double surface_spring_energy_J() const;
  double energy_J() const { return kinetic_energy_J() + virtual_spring_energy_J() + surface_spring_energy_J(); }

  // --- integration facts ---
  double node_mass_kg() const { return mass_kg_; }
  double time_step_s() const { return settings_.time_step_s; }
  /// Gershgorin-safe critical step of the explicit integrator (s).
  double critical_time_step_s() const { return dt_crit_s_; }
  /// Upper bound on omega_max^2 (rad^2/s^2) used for dt_crit.
  double omega_max_squared_bound() const { return omega_max_sq_; }
  int explicit_substeps() const { return substeps_; }
  /// True when the explicit integrator does every step implicitly (too many substeps).
  bool explicit_falls_back_to_implicit() const { return explicit_fallback_; }
  const ForceMeshParams& params() const { return params_; }

 private:
  void explicit_substep(double dt, double z0);
  /// Backward-Euler solve of the free nodes for rhs_ (+ b z0 added by the caller) into work_.
  void implicit_solve();
  void update_derived();
  /// A stiffening mesh keeps its state on the cells (cell_state_z_, cell_state_v_);
  /// the per-node vectors and the ring means are expanded from them when asked.
  void update_nodes() const;
  void update_ring_means() const;
  /// Mean deflection of ring j (0-based) summed over its nodes in node order (m).
  double ring_mean_from_cells(int j) const;
  void layout(const ContactSurface& surface, const SurfacePoint& contact);
  void set_frame(const SurfacePoint& contact);
  void project_node(int i);
  /// Free-node state after one step from (z_, v_) with contact deflection
  /// z0_old -> z0_new, written to (z_, v_) (used at construction for the unit response).
  void step_free_nodes(double z0_old, double z0_new);
  /// The lattice's cells (core/src/lattice_cells.hpp): cell_of_, cell_rep_, cell_size_, pairs_, contact_pairs_.
  void setup_cells();
  // --- stiffening mesh ---
  void setup_nonlinear();
  // The constructor's phases (linear mesh): the static influence vector and
  // stiffness; explicit stability, substeps and the integrator; the implicit
  // system's LDLT factors in plain arrays; the unit response of one step.
  void compute_static_influence();
  void choose_integration();
  void factor_implicit_system();
  void compute_unit_step_response();
  void predict_linear();
  /// predict() of a stiffening mesh: the step solved at contact deflection z0_star and linearised there.
  void predict_nonlinear(double z0_star);
  /// Residual of the free nodes' step equations at (cell_z_, contact z0), one per free cell, into
  /// cell_residual_; returns its max norm.
  double nonlinear_residual(double z0);
  /// Tangent of the cells' step equations at the state of the last nonlinear_residual() (the
  /// springs' tangent it kept) factorised; throws std::runtime_error if not SPD.
  void factorize_tangent();
  /// Newton from cell_z_ to the step's solution at contact deflection z0 (scale: the deflections'
  /// magnitude, m); returns the last full Newton step (m).
  double newton_solve_cells(double z0, double scale);
  /// Solves the step to contact deflection z0 from the committed cell state into
  /// (cell_pz_, cell_pv_), with its sensitivity in (cell_qz_, cell_qv_).
  void solve_nonlinear_step(double z0);

  ForceMeshParams params_;
  MeshIntegrationSettings settings_;
  HexLattice lattice_;
  double mass_kg_ = 0.0;
  double static_stiffness_N_per_m_ = 0.0;
  double dt_crit_s_ = 0.0;
  double omega_max_sq_ = 0.0;
  int substeps_ = 1;
  bool explicit_fallback_ = false;
  bool use_implicit_ = false;

  Eigen::Matrix3Xd rest_, normals_;
  mutable Eigen::Matrix3Xd positions_;
  mutable bool positions_stale_ = false;  ///< z_ changed since positions_ was computed
  // Layout frame: contact point, normal and in-plane axes; nodes >= next_projection_ are
  // still in the tangent plane (relayout) and wait for their projection onto *layout_surface_.
  const ContactSurface* layout_surface_ = nullptr;
  Eigen::Vector3d frame_origin_ = Eigen::Vector3d::Zero(), frame_normal_ = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d frame_e1_ = Eigen::Vector3d::UnitX(), frame_e2_ = Eigen::Vector3d::UnitY();
  int next_projection_ = 0;
  // Node state. A stiffening mesh's own state is on the cells (below); z_ and v_
  // are then its expansion to the nodes, made when asked (nodes_stale_).
  mutable Eigen::VectorXd z_, v_;
  mutable bool nodes_stale_ = false;
  Eigen::VectorXd influence_, rhs_, work_;
  Eigen::VectorXd pz_, pv_;  ///< linear mesh: predicted free-node state for z0 = 0 (index 0 unused)
  Eigen::VectorXd qz_, qv_;  ///< linear mesh: unit response of the free nodes to z0 = 1 at the end of a step
  double max_abs_deflection_m_ = 0.0;
  double max_abs_velocity_m_per_s_ = 0.0;
  double predicted_intercept_N_ = 0.0;
  double reaction_slope_N_per_m_ = 0.0;
  double predicted_z0_ = 0.0;  ///< contact deflection the prediction is linearised at (0: linear mesh)
  bool predicted_ = false;
  // The lattice's cells (cell 0 = the contact node; free cell index a = cell - 1), on which the
  // implicit step and the stiffening mesh's step are solved. Stiffening mesh: the step's tangent
  // on its fixed pattern (diagonal entries 0..mf-1, then one entry per pair of free cells),
  // scratch vectors.
  struct CellPair {
    int a = 0, b = 0;           ///< cells, a < b
    double edges = 0.0;         ///< springs between them
    double per_node_a = 0.0;    ///< neighbours in b of each node of a (edges / |a|)
    double per_node_b = 0.0;    ///< neighbours in a of each node of b (edges / |b|)
  };
  bool nonlinear_ = false;
  detail::TangentFactorization tangent_;
  std::vector<double> tangent_values_;
  std::vector<int> cell_of_, cell_rep_;        ///< cell of each node; first node of each cell
  Eigen::VectorXd cell_size_;                  ///< nodes per cell
  std::vector<CellPair> pairs_;                ///< adjacent free cells
  std::vector<CellPair> contact_pairs_;        ///< cells adjacent to the contact node (a = 0)
  double step_mass_term_ = 0.0;                ///< m/dt^2 + c/dt (implicit), 0 (quasi-static)
  Eigen::VectorXd cell_state_z_, cell_state_v_;  ///< committed deflection and rate per cell ([0] = contact)
  Eigen::VectorXd cell_pz_, cell_pv_;          ///< predicted state per cell at the linearisation point
  Eigen::VectorXd cell_qz_, cell_qv_;          ///< its sensitivity to the contact deflection per cell
  Eigen::VectorXd cell_z_, trial_cell_z_;      ///< Newton iterate per cell ([0] = contact)
  std::vector<double> pair_stiffness_, contact_pair_stiffness_;  ///< springs' tangent at the last residual
  std::vector<double> cell_virtual_stiffness_;                   ///< virtual springs' tangent there, per cell
  Eigen::VectorXd inertial_target_;            ///< z_hat of the step equations per free cell
  Eigen::VectorXd cell_residual_, newton_step_;
  int newton_iterations_ = 0;
  bool tangent_ready_ = false;  ///< the tangent has been factorised at least once
  mutable Eigen::VectorXd ring_mean_m_;
  mutable bool ring_means_stale_ = false;
  Eigen::VectorXd ring_size_;
  std::vector<int> ring_node_start_, ring_nodes_;  ///< each ring's nodes in node order (CSR)
  std::vector<int> ring_cell_start_, ring_cells_;  ///< each ring's distinct cells (CSR)

  // LDLT factors of the implicit system over the free cells (index a = cell - 1; linear mesh):
  // P A P^T = L D L^T, L unit lower, stored column-wise (CSC, strictly lower part).
  std::vector<int> l_col_start_, l_row_;
  std::vector<double> l_val_;
  Eigen::VectorXd d_inv_;
  std::vector<int> perm_;  ///< (P b)[perm_[k]] = b[k]
};

}  // namespace puncture
