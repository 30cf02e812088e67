// volumetric_model.hpp: a needle insertion into a tetrahedral mesh of the
// slab with one InternalForceLaw (mass-spring, linear / StVK / visco-elastic
// tensor-mass), integrated in time through SUNDIALS.
//
// Dynamics (seed 001: M x'' = -K x - Y x', here with the law's nonlinear
// internal forces f(x, v, q)): lumped masses m_a = sum_T rho_T V_T / 4,
// Rayleigh damping Y = alpha M + beta K0 (K0: the law's tangent at rest;
// ComparisonSettings::mass_damping_per_s, stiffness_damping_s; beta damps the
// mesh's high modes, whose transients would otherwise hold the steps at
// fractions of a millisecond):
//     x' = v,  M v' = f(x, v, q) - Y v,  q' = law's internal variables.
// State y = [x (3N), v (3N), q]. Boundary conditions as the FEM reference:
// base z = -total thickness and side r = R fixed.
//
// Needle (blunt, radius a, along -z on the axis), as the FEM reference and the
// real-time model decide it:
//   * only the active layer (first not punctured) is pressed; a node of its
//     top surface with rest radius r <= a joins the contact set when the tip
//     reaches it (z_node >= z_tip): it is put at z_tip and then moves with the
//     needle (prescribed: x' = needle velocity, lateral position held);
//   * contact force = sum over contact nodes of the z component of the
//     internal force on them (N, positive resisting insertion);
//   * during withdrawal a contact node whose reaction turns to tension is
//     released (no adhesion), and no node joins the contact set (a surface
//     recovering behind the retreating tip would otherwise chatter between
//     contact and release at every step);
//   * breakthrough: the layer's rule of the scene (layer_breakthrough.hpp):
//     a critical contact force, a critical work of the needle on the layer, or
//     the ring-w rule (ring_criterion.hpp) on the deflection of the active
//     layer's top surface at the force-mesh lattice points, measured from the
//     moment the needle first touched the layer; checked while the needle
//     advances (as the force mesh, whose deflections only shrink when the
//     needle is withdrawn), from the step after the contact started (a
//     surface put onto the tip is first brought to equilibrium). The layer's
//     needle-column tetrahedra (TetMesh::needle_column) are then removed (the
//     cut), its contact nodes released (the surface springs back) and the
//     next layer becomes active (it may be touched in the same step). When the
//     next layer's surface lies below the tip (it is put onto the tip by more
//     than 20 um), the free nodes are brought to static equilibrium at once
//     (as the FEM reference does), instead of a dynamic impulse.
// Every state change (contact, release, puncture, a change of needle speed)
// re-initialises the integrator at that time; so does a failed integration
// (error or convergence test failing repeatedly), once, from the last
// haptic step, before the failure is reported. Before the needle first touches
// the tissue nothing is integrated (the mesh rests, y' = 0).
//
// Implicit integration: CVODE BDF of order at most 2 (the A-stable ones: the
// lightly damped oscillations of an elastic mesh make BDF3-5 unstable and
// their steps collapse); its Newton matrix I - gamma J is
// preconditioned exactly (up to lagging) by eliminating x:
//   ((1 + gamma alpha) M + gamma beta K0 + gamma^2 K) b = M r_v - gamma K r_x,  a = r_x + gamma b
// with the law's tangent K at the last setup (prescribed and fixed degrees of
// freedom eliminated), factorised by a sparse Cholesky (sparse_spd_factor.hpp); laws with an exact
// tangent also give the Jacobian-vector product from it. The factorisation is
// reused while gamma stays within a factor 5 of the one it was made with and
// no Newton iteration has failed to converge since it was made, across new
// tangents and contact changes (a lagged preconditioner; a puncture, which
// removes elements, drops it);
// the visco-elastic law's internal variables q (q' = g dS_e/dt - q / tau) are
// eliminated too: their residual enters the velocity equation through their
// nodal forces, and q's correction follows from the velocity one;
// while gamma^2 times the Gershgorin bound of M^-1 K is below 1/4 (the small
// steps after a restart) the diagonal of the matrix is used instead.
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCholesky>

#include "puncture/comparison/block_sparse.hpp"
#include "puncture/comparison/comparison_model.hpp"
#include "puncture/comparison/internal_forces.hpp"
#include "puncture/comparison/layer_breakthrough.hpp"
#include "puncture/comparison/sparse_spd_factor.hpp"
#include "puncture/comparison/sundials_integrator.hpp"
#include "puncture/meshing/tet_mesh.hpp"

namespace puncture::comparison {

using meshing::TetMesh;  // the comparison models work on meshing's tetrahedral slab

struct VolumetricSettings {
  IntegratorKind integrator = IntegratorKind::ImplicitBdf;
  double relative_tolerance = 1e-4;
  double absolute_tolerance_m = 1e-7;
  double mass_damping_per_s = 20.0;
  double stiffness_damping_s = 1e-3;
  /// No time integration: static equilibrium at every step (contact nodes at
  /// the tip, modified Newton on the law's tangent, factorisation kept while
  /// the contact set is unchanged and Newton converges). Used by the
  /// mass-spring identification against the quasi-static FEM.
  bool quasi_static = false;
  /// Keep the Newton matrix's factorisation across new tangents and contact
  /// changes while Newton converges with it (false: refactorise at every
  /// Jacobian update and contact change, as before; for tests).
  bool lag_preconditioner = true;
};
VolumetricSettings volumetric_settings(const Scene& scene);

/// Interpolation of the displacement of one layer's top surface at planar
/// points: each point is located in a triangle of the layer's top face
/// (faces of its tetrahedra lying on the plane z = top) and gets the three
/// nodes and barycentric weights.
class LayerSurfaceProbe {
 public:
  LayerSurfaceProbe() = default;
  LayerSurfaceProbe(const TetMesh& mesh, int layer, double top_z_m, const std::vector<Eigen::Vector2d>& points_m);
  std::size_t size() const { return weights_.size(); }
  bool found(std::size_t i) const { return found_[i] != 0; }
  /// -u_z (m, > 0 into the tissue) at every point (0 where not found).
  std::vector<double> deflection_m(const Eigen::VectorXd& x, const Eigen::Matrix3Xd& rest) const;

 private:
  std::vector<Eigen::Vector3i> nodes_;
  std::vector<Eigen::Vector3d> weights_;
  std::vector<char> found_;
};

class VolumetricNeedleModel final : public ComparisonModel, private OdeSystem {
 public:
  /// mesh: shared by every model built from it; law: built on the same mesh.
  VolumetricNeedleModel(const Scene& scene, std::shared_ptr<const TetMesh> mesh, std::unique_ptr<InternalForceLaw> law,
                        const VolumetricSettings& settings, std::string description);
  ~VolumetricNeedleModel() override;

  std::string name() const override { return law_->name(); }
  std::string description() const override { return description_; }
  double step(const NeedleState& needle) override;
  LayerState layer_state(std::size_t layer) const override { return layers_[layer].state; }
  double break_force_N(std::size_t layer) const override { return layers_[layer].break_force_N; }
  std::vector<double> surface_deflection_m(std::size_t layer, const std::vector<double>& r_m) const override;
  ModelSize model_size() const override;
  bool has_volume() const override { return true; }
  VolumeFrame volume_frame() const override;
  ElementInversion element_inversion() const override;
  std::string integrator_report() const override;
  long recovered_steps() const override;

  const InternalForceLaw& law() const { return *law_; }
  const Eigen::VectorXd& state() const { return y_; }
  int contact_node_count() const;
  /// Internal + kinetic energy (J), for tests.
  double mechanical_energy_J() const;

 private:
  enum class Dof : unsigned char { Free, Contact, Fixed };
  struct LayerRuntime {
    double top_z_m = 0.0;
    std::vector<int> candidates;  ///< top-surface nodes with rest r <= needle radius
    LayerState state = LayerState::Untouched;
    bool contact_started = false;
    LayerBreakthroughRule breakthrough;
    LayerSurfaceProbe ring_probe;
    std::vector<double> baseline_m;  ///< ring-point deflections when the contact started
    double break_force_N = std::numeric_limits<double>::quiet_NaN();  ///< contact force at the break
  };

  // OdeSystem
  int size() const override { return static_cast<int>(y_.size()); }
  int rhs(double t, const double* y, double* ydot) override;
  bool has_preconditioner() const override;
  int preconditioner_setup(double t, const double* y, bool jok, bool& updated, double gamma) override;
  int preconditioner_solve(double t, const double* y, const double* r, double* z, double gamma) override;
  bool has_jacobian_times() const override;
  int jacobian_times(double t, const double* y, const double* v, double* Jv) override;

  void compute_masses();
  void compute_rest_tangent();
  /// Drops every kept factorisation of the Newton matrix (a new tangent or mesh).
  void drop_factors();
  void compute_forces(const Eigen::VectorXd& y, Eigen::VectorXd& f) const;
  /// A linear law's force on node a along z (N) in the current state:
  /// -(K0 (x - X + beta v)) at that row, from K0's column (K0 symmetric): a
  /// few dozen products where compute_forces sweeps every element.
  double linear_force_z_N(int a) const;
  bool update_contacts(double z_tip_m, double velocity_z_m_per_s, bool withdrawing);
  /// After a relaxation to equilibrium with the tip at z_tip_m: the needle's
  /// layer, if its rule reads the contact force, is checked on this state and
  /// broken when the force reaches its critical one. True when it broke.
  bool break_after_relaxation(double z_tip_m);
  /// Breaks the needle's layer, which carried load_at_break_N (N) at the break.
  void puncture_active_layer(double load_at_break_N);
  /// Static equilibrium of the free nodes with the current contact set
  /// (modified Newton on the law's tangent); free velocities set to zero.
  /// False when the tangent could not be factorised (the state is left to the dynamics).
  bool relax_to_equilibrium();
  /// The law's exact tangent at `state` with the prescribed dofs eliminated,
  /// factorised for relax_to_equilibrium; false if the factorisation failed.
  bool factorise_static_tangent(const Eigen::VectorXd& state);
  double contact_force_N();
  // The phases of step(): equilibrium at every step (quasi-static mode); the
  // first call (integrator set up at the needle's state); one haptic step of
  // the dynamics (contact nodes moved with the needle, integrator advanced,
  // restarted once after a failure).
  void step_quasi_static(double t, double z_tip_m, bool withdrawing);
  void start_integration(double t, double z_tip_m, double velocity_z_m_per_s);
  void advance_dynamics(double t, double z_tip_m, double velocity_z_m_per_s);
  Eigen::Matrix3Xd deformed_points() const;

  const Scene* scene_;
  std::shared_ptr<const TetMesh> mesh_;
  std::unique_ptr<InternalForceLaw> law_;
  VolumetricSettings settings_;
  std::string description_;
  int nodes_ = 0;
  int extra_ = 0;
  double needle_radius_m_ = 0.0;

  Eigen::VectorXd rest_;        ///< 3N rest positions
  Eigen::VectorXd mass_;        ///< 3N lumped masses (per dof)
  std::vector<Dof> dof_;        ///< per node
  std::vector<std::uint8_t> removed_;
  std::vector<LayerRuntime> layers_;
  std::size_t active_ = 0;

  Eigen::VectorXd y_;           ///< state at time_
  double time_ = 0.0;
  bool started_ = false;
  double needle_velocity_z_ = 0.0;  ///< velocity of the contact nodes (m/s, z component)
  std::unique_ptr<SundialsIntegrator> integrator_;
  long events_ = 0;

  // Preconditioner data (implicit).
  NodeBlockMatrix tangent_;            ///< K at the last setup
  NodeBlockMatrix rest_tangent_;       ///< K0 (for the stiffness-proportional damping, and a linear law's forces)
  Eigen::SparseMatrix<double> system_; ///< (1 + gamma alpha) M + (gamma^2 + gamma beta) K, eliminated
  /// A factorisation is used for gammas within this factor of its own.
  static constexpr double kFactorReuse = 10.0;
  /// Factorisations kept (about 55 MB each on the default slab's mesh).
  static constexpr int kFactorsKept = 8;
  GammaFactorPool factors_{kFactorReuse, kFactorsKept};
  const SparseSpdFactor* factor_in_use_ = nullptr;  ///< the preconditioner's (one of factors_)
  bool have_tangent_ = false;
  bool mass_only_ = false;          ///< the last setup chose the diagonal preconditioner
  long factor_convergence_failures_ = 0;  ///< integrator's convergence failures when the last factor was made
  long failure_restarts_ = 0;  ///< restarts after the integrator failed (step())
  double omega_squared_bound_ = 0.0;
  Eigen::VectorXd diagonal_;
  long factorisations_ = 0;
  long relaxations_ = 0;
  /// The static relaxation's tangent K alone (no mass: at most positive
  /// semi-definite for a mass-spring network): after a contact jump of the
  /// dynamics CHOLMOD's Cholesky (Eigen's LDL^T where K is not positive
  /// definite); in the quasi-static mode Eigen's LDL^T, whose equilibria the
  /// quasi-static identification was made with.
  SparseSpdFactor relax_factor_;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> static_solver_;
  bool static_pattern_analysed_ = false;
  bool static_factor_valid_ = false;
  long relaxation_factorisations_ = 0;
  double snap_relax_threshold_m_ = 20e-6;
  double checked_force_N_ = 0.0;  ///< contact force the last breakthrough check computed on the current state (NaN: none)
  long mass_only_setups_ = 0;
  double factorisation_seconds_ = 0.0;
  std::vector<double> decay_rates_;
  mutable Eigen::VectorXd work_f_, work_a_;
  const double* yp_current_ = nullptr;  ///< the state preconditioner_solve was called at
};

}  // namespace puncture::comparison
