// finite_strain_solver.hpp: quasi-static total-Lagrangian finite-strain solver
// on a distributed hexahedral mesh (deal.II, Trilinos, MPI).
//
// In:  a parallel::distributed::Triangulation<3> (coordinates in m; each
//      cell's material_id indexes `materials`), the per-material laws
//      (hyperelastic_materials.hpp), SolverSettings; per load step the
//      prescribed total displacements of some degrees of freedom (m) and
//      optional dead-load tractions (Pa, per reference area).
// Out: the displacement field u (m, FE_Q^3 of the chosen degree), internal
//      forces (N) on any set of dofs (reactions), per-cell fields (J, von
//      Mises Cauchy stress in Pa, maximum principal stretch).
//
// Formulation. Residual R(u) = f_int(u) - f_ext = dE/du of the reduced energy
//   E(u) = sum_cells int Psi_iso(C) dV + int Psi_vol(Jtilde) dV - f_ext . u
// where Jtilde is the dilatation:
//   * VolumetricFormulation::one_field:   Jtilde = J pointwise (classical
//     compressible formulation; locks for nu -> 0.5 with low-order elements);
//   * VolumetricFormulation::three_field: Hu-Washizu u-p-Jtilde (step-44) with
//     discontinuous pressure and dilatation of degree k-1 (Q1-P0 = mean
//     dilatation, Q2-P1). Both extra fields are eliminated exactly at the
//     element level: Jtilde = Pi(J) (L2 projection on the cell in the
//     reference volume), p = Pi(dPsi_vol/dJ(Jtilde)); the condensed tangent is
//     K_uu + B^T M^{-1} K_JJ M^{-1} B. The global system is displacement-only
//     and symmetric, so it is solved with CG + Trilinos AMG.
// Removed ("void") cells use small-strain linear elasticity with
// void_stiffness_fraction x the layer's Young's modulus (no J, never inverts).
//
// Newton: each iteration prescribes the remaining gap (target - u) on the
// constrained dofs, solves K du = -R, and backtracks (halving) while the trial
// state has an inverted element (J <= 0 or a non-finite value) or, once the
// constraints are met, while the free residual does not decrease. On failure
// the state of the last converged step is restored and solve_step() reports
// it (the caller cuts the load step). Nothing non-finite is ever kept.
//
// Cost. The linear solves are inexact (inexact Newton): CG stops at
// linear_relative_tolerance x ||b|| or once the linear residual is a tenth of
// the Newton target, whichever is looser; the Newton test uses the exact
// residual, so the converged state is as accurate as with exact solves. The
// AMG hierarchy is built at the first iteration of a step and reused by the
// later ones. A step may start from an extrapolated state (solve_step's
// predictor_scale: u + s x the previous step's increment), which removes most
// of the first correction while the load path is smooth.
//
// Continuation (used for the spring-back after a puncture, where releasing a
// deep indentation at once defeats Newton). Two homotopies the caller lowers
// from 1 to 0 step by step:
//  * gradual removal: remove_cells(..., true) keeps the internal forces the
//    removed cells exerted at the moment of removal as a frozen nodal load,
//    scaled by set_released_force_fraction() (the force-release technique of
//    excavation analysis); at fraction 1 the state is still in equilibrium;
//  * anchor springs (set_anchor_springs) tie chosen dofs to their
//    displacement at that moment, with a stiffness scaled by
//    set_anchor_spring_scale().
//
// Viscoelastic layers (set_viscoelastic_layers): a material with a Prony
// series becomes the finite-strain viscoelastic law of
// viscoelastic_material.hpp (Simo 1987 / Holzapfel 2000, Sec. 6.10) on its
// isochoric part, the material given to the constructor being its long-term
// law; the volumetric part stays elastic (and is condensed as above). Time
// enters only through the history: each quadrature point of such a cell keeps
// (Q_i, S_iso^inf) of the last committed state; solve_step() advances it by
// set_time_step()'s dt (frozen during the Newton iterations, so the tangent
// is exact); commit_time_step() makes the current state the committed one and
// sets dt back to 0 (a state at the same instant: the instantaneous response).
// Snapshots carry the history, so restoring one goes back in time as well.
// Without viscoelastic layers nothing of this is allocated or evaluated.
#pragma once

#include <deal.II/base/point.h>
#include <deal.II/base/timer.h>
#include <deal.II/distributed/tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_vector.h>

#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <puncture/fem/hyperelastic_materials.hpp>
#include <puncture/fem/viscoelastic_material.hpp>

namespace puncture::fem {

enum class VolumetricFormulation { one_field, three_field };

/// Numerical settings of the solver.
struct SolverSettings {
  unsigned int degree = 1;  ///< displacement element degree: 1 (Q1) or 2 (Q2)
  VolumetricFormulation formulation = VolumetricFormulation::three_field;
  int max_newton_iterations = 25;
  /// Converged when the free residual <= tolerance x force scale (the larger of
  /// the reaction norm, the external load norm and the largest free residual of
  /// the step) and the prescribed values are met.
  double newton_tolerance = 1e-8;
  double absolute_residual_floor_N = 1e-13;  ///< converged below this whatever the scale
  int max_line_search_halvings = 8;
  /// > 0: give up (so that a caller that can cut the step does so early)
  /// after this many consecutive iterations whose line search had to shorten
  /// the step to <= 1/8; 0: never (such iterations often recover).
  int max_stalled_iterations = 0;
  /// When the backtracking line search (on the residual norm) can only take a
  /// step <= 1/8, search along the Newton direction for a stationary point of
  /// the potential instead (Matthies & Strang 1979: the projected residual
  /// du . R(u + alpha du) reduced to half its value at alpha = 0 by regula
  /// falsi) and take that step if it is longer. Under strong curvature (a
  /// released crack's spring-back) the residual norm rises along a step that
  /// still lowers the energy; the norm's search then crawls at 1/8.
  bool energy_line_search_fallback = true;
  /// CG stop: ||r|| <= max(tol ||b||, 0.1 x Newton target); loose on purpose
  /// (inexact Newton, see the file comment).
  double linear_relative_tolerance = 1e-4;
  /// Rebuild the AMG hierarchy at every Newton iteration (true) or once per step.
  bool rebuild_preconditioner_every_iteration = false;
  bool direct_linear_solver = false;         ///< sparse direct (MUMPS) instead of CG + AMG
  double void_stiffness_fraction = 1e-4;     ///< E_void / E_layer for removed cells
  bool verbose = false;                      ///< convergence table on rank 0
};

/// What one solve_step() did.
struct NewtonReport {
  bool converged = false;
  int iterations = 0;           ///< Newton iterations (linear solves)
  int linear_iterations = 0;    ///< total CG iterations
  double residual_N = 0.0;      ///< final free residual norm
  double force_scale_N = 0.0;   ///< scale the tolerance multiplied
  std::string failure;          ///< why it failed (empty if converged)
  std::vector<std::string> table;  ///< one line per iteration
};

/// A degree of freedom with its support point in the reference configuration.
struct DofPoint {
  dealii::types::global_dof_index dof;
  unsigned int component;  ///< 0 = x, 1 = y, 2 = z
  dealii::Point<3> X;      ///< m
};

/// Per locally owned active cell (index = active_cell_index; other entries 0).
struct CellFields {
  std::vector<double> jacobian;                  ///< cell mean of J
  std::vector<double> von_mises_Pa;              ///< cell mean of the von Mises Cauchy stress
  std::vector<double> max_principal_stretch;     ///< cell maximum over quadrature points
  std::vector<double> material_id;
  std::vector<double> removed;                   ///< 1 for removed (void) cells
};

class FiniteStrainSolver {
 public:
  using Triangulation = dealii::parallel::distributed::Triangulation<3>;
  using CellIterator = dealii::DoFHandler<3>::active_cell_iterator;

  FiniteStrainSolver(Triangulation& triangulation, std::vector<LayerMaterial> materials,
                     const SolverSettings& settings);
  ~FiniteStrainSolver();

  /// One Prony series per material (an empty one: elastic), before setup():
  /// material l becomes viscoelastic with the constructor's law as its
  /// long-term (fully relaxed) law (see the file comment). Throws
  /// std::invalid_argument for a wrong count or a bad term.
  void set_viscoelastic_layers(const std::vector<std::vector<PronyTerm>>& prony_per_material);
  bool has_viscoelastic_layers() const { return !viscoelastic_.empty(); }

  /// Distributes the dofs, builds the sparsity pattern, sets u = 0 (and the
  /// viscoelastic history to the undisturbed past).
  void setup();

  /// Time (s) the next solve_step()s advance the viscoelastic history from its
  /// committed state (finite, >= 0; 0 after setup() and commit_time_step()).
  /// No effect without viscoelastic layers.
  void set_time_step(double dt_s);
  /// The current (converged) state becomes the committed viscoelastic state at
  /// the end of the time step; the time step is set back to 0. Call once per
  /// accepted step.
  void commit_time_step();

  MPI_Comm mpi_communicator() const;
  const dealii::DoFHandler<3>& dof_handler() const { return dof_handler_; }
  const dealii::FESystem<3>& fe() const { return fe_; }
  dealii::types::global_dof_index n_dofs() const { return dof_handler_.n_dofs(); }
  const SolverSettings& settings() const { return settings_; }

  /// Every locally relevant dof with its support point (m) and component.
  std::vector<DofPoint> locally_relevant_dof_points() const;

  /// Target total displacements (m) of prescribed dofs. Give at least every
  /// locally relevant prescribed dof; every rank must agree on shared ones.
  void set_prescribed_displacements(std::map<dealii::types::global_dof_index, double> targets);
  const std::map<dealii::types::global_dof_index, double>& prescribed_displacements() const {
    return targets_;
  }

  /// Dead-load traction (Pa, per reference area) on faces with this boundary id.
  void set_dead_load_traction(dealii::types::boundary_id id, const dealii::Tensor<1, 3>& traction_Pa);

  /// Marks cells removed (void material) where predicate(cell) is true.
  /// Cells already removed stay removed. release_gradually: the internal
  /// forces the newly removed cells exerted (minus those of their void
  /// material) become a frozen load at fraction 1 (see the file comment);
  /// otherwise the frozen load is cleared. Collective.
  void remove_cells(const std::function<bool(const CellIterator&)>& predicate, bool release_gradually = false);
  /// Fraction (0..1) of the frozen removal load still applied. Like the
  /// anchor-spring setters below, it takes effect at the next solve_step();
  /// until then the residual queries report the last assembled state.
  void set_released_force_fraction(double fraction);
  bool is_removed(const CellIterator& cell) const;

  /// Newton solve of the current load step, starting from u + predictor_scale
  /// x (increment of the last converged step) when that state is admissible
  /// (0: start from u). On failure the previous converged state is restored.
  NewtonReport solve_step(double predictor_scale = 0.0);

  /// The state a caller can go back to (e.g. to bisect a load step): the
  /// displacement, the last step's increment, the committed viscoelastic
  /// history and the time step. Removed cells, prescribed values and springs
  /// are not part of it.
  struct Snapshot {
    dealii::TrilinosWrappers::MPI::Vector solution, last_increment;
    std::vector<std::vector<ViscoelasticHistory>> viscous_history;
    double time_step_s = 0.0;
  };
  Snapshot snapshot() const { return {solution_, last_increment_, viscous_history_, time_step_s_}; }
  /// Restores a snapshot and re-evaluates the residual (collective).
  void restore(const Snapshot& snapshot);

  /// Linear springs (N/m per dof) pulling the given dofs toward their current
  /// displacement (anchor = u now). Prescribed dofs ignore their spring.
  /// Replaces any earlier springs; an empty map removes them.
  void set_anchor_springs(const std::map<dealii::types::global_dof_index, double>& stiffness_N_per_m);
  /// Multiplies the stiffness given to set_anchor_springs (anchors kept); 0
  /// switches the springs off.
  void set_anchor_spring_scale(double scale);
  bool has_anchor_springs() const { return !anchors_.empty() && anchor_scale_ > 0.0; }

  /// Ghosted total displacement (m).
  const dealii::TrilinosWrappers::MPI::Vector& solution() const { return solution_ghosted_; }
  /// u at one locally relevant dof (m).
  double displacement(dealii::types::global_dof_index dof) const { return solution_ghosted_[dof]; }

  /// Sum of the internal force (N) f_int - f_ext on the given dofs at the
  /// last converged state: each dof counted once (by its owner), MPI-summed.
  /// For prescribed dofs this is the force the supports apply to the body.
  double sum_of_residual(const std::vector<dealii::types::global_dof_index>& dofs) const;

  /// Maximum principal stretch over the quadrature points of the locally
  /// owned, not removed cells selected by predicate (MPI max; 1 if none).
  double max_principal_stretch(const std::function<bool(const CellIterator&)>& predicate) const;

  CellFields cell_fields() const;

 private:
  struct AssemblyResult {
    bool valid = true;  ///< false: an inverted or non-finite quadrature point somewhere
  };
  // --- solve_step(), one Newton step in phases --------------------------------
  struct Step;     ///< what the phases of one step share (defined in the .cc)
  struct Iterate;  ///< one Newton iterate: residual, force scale, test, log line (in the .cc)
  using Failure = std::optional<std::string>;  ///< why the step fails (nullopt: it goes on)
  /// Saves the start of the step and applies the predictor if it is admissible.
  void start_step(Step& step, double predictor_scale);
  /// Assembles at solution_ (unless the line search did): free residual, force scale, convergence test.
  Failure evaluate_iterate(Step& step, Iterate& x);
  /// Newton direction: K du = -R with the increment constraints (solve_linear).
  Failure newton_direction(Step& step, Iterate& x);
  /// Backtracking line search along du from solution_: the step length alpha and step.trial.
  Failure line_search(Step& step, Iterate& x, double& alpha);
  /// du . R over the free dofs (the prescribed ones left out), MPI-summed (N m).
  double free_residual_dot(const dealii::TrilinosWrappers::MPI::Vector& du) const;
  /// A converged step: its log line and the last increment.
  NewtonReport accept_step(Step& step, const Iterate& x);
  /// A failed step: the state at its start restored, the reason reported.
  NewtonReport fail_step(Step& step, const std::string& why);
  /// A line of the Newton log on rank 0 when settings_.verbose.
  void print_verbose(const std::string& line) const;

  // --- assemble(): residual_, rhs_ and (with_matrix) tangent_ at u -------------
  AssemblyResult assemble(const dealii::TrilinosWrappers::MPI::Vector& u_ghosted, bool with_matrix,
                          const dealii::AffineConstraints<double>* constraints);
  /// Anchor springs f = k (u - anchor) on free, locally owned dofs (into the
  /// Newton system too when constraints are given).
  void add_anchor_springs(const dealii::TrilinosWrappers::MPI::Vector& u,
                          const dealii::AffineConstraints<double>* constraints);
  /// The frozen removal load at released_fraction_ (a dead load).
  void add_released_load(const dealii::AffineConstraints<double>* constraints);
  /// Constraints of the Newton update at state u (ghosted): du = target - u
  /// on the prescribed dofs.
  void increment_constraints(const dealii::TrilinosWrappers::MPI::Vector& u,
                             dealii::AffineConstraints<double>& constraints) const;
  unsigned int solve_linear(dealii::TrilinosWrappers::MPI::Vector& du, double absolute_tolerance,
                            bool rebuild_preconditioner);
  /// ML AMG of the current tangent (rigid-body modes as near null space) into amg_.
  void build_preconditioner();
  double free_residual_norm() const;
  double reaction_norm() const;
  double external_load_norm() const;
  double max_constraint_gap() const;

  Triangulation& triangulation_;
  std::vector<LayerMaterial> materials_;
  SolverSettings settings_;
  dealii::FESystem<3> fe_;
  dealii::DoFHandler<3> dof_handler_;
  dealii::IndexSet locally_owned_;
  dealii::IndexSet locally_relevant_;

  std::map<dealii::types::global_dof_index, double> targets_;
  std::map<dealii::types::boundary_id, dealii::Tensor<1, 3>> tractions_;
  std::vector<char> removed_;  ///< per active cell index
  /// Per material: its viscoelastic law, or none (elastic). Empty: no viscoelastic layers.
  std::vector<std::optional<ViscoelasticMaterial<LayerMaterial>>> viscoelastic_;
  /// Per active cell index: the committed history of each quadrature point
  /// (locally owned cells of viscoelastic materials; others empty).
  std::vector<std::vector<ViscoelasticHistory>> viscous_history_;
  double time_step_s_ = 0.0;  ///< s, see set_time_step()
  /// The undisturbed past at every quadrature point of a viscoelastic cell; dt = 0.
  void allocate_viscous_history();
  /// The viscoelastic law of a cell (nullptr: elastic or removed).
  const ViscoelasticMaterial<LayerMaterial>* viscoelastic_of(const CellIterator& cell) const;
  /// Its points' committed history (nullptr: elastic or removed).
  const std::vector<ViscoelasticHistory>* viscous_history_of(const CellIterator& cell) const;
  /// locally owned dof -> (component, support point), for the AMG near null space
  std::map<dealii::types::global_dof_index, std::pair<unsigned int, dealii::Point<3>>> owned_support_;

  struct AnchorSpring {
    double stiffness_N_per_m;
    double anchor_m;
  };
  std::map<dealii::types::global_dof_index, AnchorSpring> anchors_;  ///< locally owned dofs only
  double anchor_scale_ = 1.0;
  dealii::TrilinosWrappers::MPI::Vector released_force_;  ///< frozen removal load (N, owned)
  double released_fraction_ = 0.0;
  std::unique_ptr<dealii::TrilinosWrappers::PreconditionAMG> amg_;
  dealii::TrilinosWrappers::MPI::Vector last_increment_;  ///< of the last converged step (owned)
  dealii::TrilinosWrappers::SparseMatrix tangent_;
  dealii::TrilinosWrappers::MPI::Vector rhs_;            ///< -R with constraints applied
  dealii::TrilinosWrappers::MPI::Vector residual_;       ///< R = f_int - f_ext, unconstrained
  dealii::TrilinosWrappers::MPI::Vector solution_;       ///< owned
  dealii::TrilinosWrappers::MPI::Vector solution_ghosted_;
  /// Wall time by section ("assemble", "linear solve"); the Newton log's
  /// per-iteration times are differences of its totals. Never printed by itself.
  dealii::TimerOutput timer_{std::cout, dealii::TimerOutput::never, dealii::TimerOutput::wall_times};
};

}  // namespace puncture::fem
