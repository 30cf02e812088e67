// finite_strain_solver.cc: see finite_strain_solver.hpp for the formulation.
#include <puncture/fem/finite_strain_solver.hpp>
#include <puncture/fem/kinematics.hpp>

#include "backtracking_line_search.hpp"
#include "energy_line_search.hpp"
#include "solver_timing.hpp"

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_solver.h>
#include <deal.II/lac/vector.h>

#include <Epetra_MultiVector.h>
#include <Teuchos_ParameterList.hpp>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

namespace puncture::fem {
using namespace dealii;

FiniteStrainSolver::FiniteStrainSolver(Triangulation& triangulation,
                                       std::vector<LayerMaterial> materials,
                                       const SolverSettings& settings)
    : triangulation_(triangulation),
      materials_(std::move(materials)),
      settings_(settings),
      fe_(FE_Q<3>(settings.degree), 3),
      dof_handler_(triangulation) {
  if (settings_.degree != 1 && settings_.degree != 2)
    throw std::invalid_argument("FiniteStrainSolver: element degree must be 1 or 2");
  if (materials_.empty()) throw std::invalid_argument("FiniteStrainSolver: no materials");
}

FiniteStrainSolver::~FiniteStrainSolver() { dof_handler_.clear(); }

MPI_Comm FiniteStrainSolver::mpi_communicator() const { return triangulation_.get_communicator(); }

void FiniteStrainSolver::setup() {
  for (const auto& cell : triangulation_.active_cell_iterators())
    if (!cell->is_artificial() && cell->material_id() >= materials_.size())
      throw std::invalid_argument("FiniteStrainSolver: cell material id " +
                                  std::to_string(cell->material_id()) + " has no material");
  dof_handler_.distribute_dofs(fe_);
  locally_owned_ = dof_handler_.locally_owned_dofs();
  DoFTools::extract_locally_relevant_dofs(dof_handler_, locally_relevant_);
  const MPI_Comm comm = mpi_communicator();

  DynamicSparsityPattern dsp(locally_relevant_);
  DoFTools::make_sparsity_pattern(dof_handler_, dsp, AffineConstraints<double>(), false);
  SparsityTools::distribute_sparsity_pattern(dsp, locally_owned_, comm, locally_relevant_);
  tangent_.reinit(locally_owned_, locally_owned_, dsp, comm);

  rhs_.reinit(locally_owned_, comm);
  residual_.reinit(locally_owned_, comm);
  solution_.reinit(locally_owned_, comm);
  solution_ghosted_.reinit(locally_owned_, locally_relevant_, comm);
  solution_ = 0.0;
  solution_ghosted_ = solution_;
  last_increment_.reinit(locally_owned_, comm);
  released_force_.reinit(locally_owned_, comm);
  released_fraction_ = 0.0;
  anchors_.clear();
  anchor_scale_ = 1.0;
  amg_.reset();
  removed_.assign(triangulation_.n_active_cells(), 0);
  allocate_viscous_history();
  owned_support_.clear();
  for (const auto& p : locally_relevant_dof_points())
    if (locally_owned_.is_element(p.dof)) owned_support_[p.dof] = {p.component, p.X};
  assemble(solution_ghosted_, false, nullptr);
}

std::vector<DofPoint> FiniteStrainSolver::locally_relevant_dof_points() const {
  std::vector<DofPoint> out;
  std::set<types::global_dof_index> seen;
  const auto& unit_points = fe_.get_unit_support_points();
  const MappingQ1<3> mapping;
  std::vector<types::global_dof_index> dofs(fe_.n_dofs_per_cell());
  for (const auto& cell : dof_handler_.active_cell_iterators()) {
    if (cell->is_artificial()) continue;
    cell->get_dof_indices(dofs);
    for (unsigned i = 0; i < dofs.size(); ++i)
      if (seen.insert(dofs[i]).second)
        out.push_back({dofs[i], fe_.system_to_component_index(i).first,
                       mapping.transform_unit_to_real_cell(cell, unit_points[i])});
  }
  return out;
}

void FiniteStrainSolver::set_prescribed_displacements(
    std::map<types::global_dof_index, double> targets) {
  for (const auto& [dof, value] : targets)
    if (!std::isfinite(value))
      throw std::invalid_argument("FiniteStrainSolver: non-finite prescribed displacement");
  targets_ = std::move(targets);
}

void FiniteStrainSolver::set_dead_load_traction(types::boundary_id id, const Tensor<1, 3>& traction_Pa) {
  tractions_[id] = traction_Pa;
}

void FiniteStrainSolver::remove_cells(const std::function<bool(const CellIterator&)>& predicate,
                                      bool release_gradually) {
  released_fraction_ = 0.0;
  TrilinosWrappers::MPI::Vector before;
  if (release_gradually) {
    assemble(solution_ghosted_, false, nullptr);  // without any earlier frozen load
    before = residual_;
  }
  for (const auto& cell : dof_handler_.active_cell_iterators())
    if (!cell->is_artificial() && predicate(cell)) removed_[cell->active_cell_index()] = 1;
  assemble(solution_ghosted_, false, nullptr);
  if (release_gradually) {
    // Internal force of the removed cells (hyperelastic minus void law):
    // applied at fraction 1 it restores the residual of before the removal.
    released_force_ = before;
    released_force_ -= residual_;
    released_fraction_ = 1.0;
    residual_ = before;
  }
}

void FiniteStrainSolver::set_viscoelastic_layers(const std::vector<std::vector<PronyTerm>>& prony_per_material) {
  if (dof_handler_.has_active_dofs())
    throw std::logic_error("FiniteStrainSolver: set_viscoelastic_layers must come before setup()");
  if (prony_per_material.size() != materials_.size())
    throw std::invalid_argument("FiniteStrainSolver: one Prony series (possibly empty) per material, got " +
                                std::to_string(prony_per_material.size()) + " for " +
                                std::to_string(materials_.size()) + " materials");
  std::vector<std::optional<ViscoelasticMaterial<LayerMaterial>>> laws(materials_.size());
  bool any = false;
  for (std::size_t l = 0; l < materials_.size(); ++l)
    if (!prony_per_material[l].empty()) {
      laws[l] = make_viscoelastic_layer(materials_[l], prony_per_material[l]);
      any = true;
    }
  if (any) viscoelastic_ = std::move(laws);
  else viscoelastic_.clear();
}

const ViscoelasticMaterial<LayerMaterial>* FiniteStrainSolver::viscoelastic_of(const CellIterator& cell) const {
  if (viscoelastic_.empty() || removed_[cell->active_cell_index()]) return nullptr;
  const auto& law = viscoelastic_[cell->material_id()];
  return law ? &*law : nullptr;
}

const std::vector<ViscoelasticHistory>* FiniteStrainSolver::viscous_history_of(const CellIterator& cell) const {
  return viscoelastic_of(cell) ? &viscous_history_[cell->active_cell_index()] : nullptr;
}

void FiniteStrainSolver::allocate_viscous_history() {
  viscous_history_.clear();
  time_step_s_ = 0.0;
  if (viscoelastic_.empty()) return;
  const unsigned nq = QGauss<3>(settings_.degree + 1).size();
  viscous_history_.resize(triangulation_.n_active_cells());
  for (const auto& cell : dof_handler_.active_cell_iterators())
    if (cell->is_locally_owned())
      if (const auto* law = viscoelastic_of(cell))
        viscous_history_[cell->active_cell_index()].assign(nq, law->initial_history());
}

void FiniteStrainSolver::set_time_step(double dt_s) {
  if (!std::isfinite(dt_s) || !(dt_s >= 0.0))
    throw std::invalid_argument("FiniteStrainSolver: time step must be finite and >= 0 s");
  time_step_s_ = dt_s;
}

void FiniteStrainSolver::commit_time_step() {
  if (!viscoelastic_.empty()) {
    const QGauss<3> quadrature(settings_.degree + 1);
    FEValues<3> fev(fe_, quadrature, update_gradients);
    const FEValuesExtractors::Vector displacement(0);
    std::vector<Tensor<2, 3>> grad_u(quadrature.size());
    for (const auto& cell : dof_handler_.active_cell_iterators()) {
      if (!cell->is_locally_owned()) continue;
      const auto* law = viscoelastic_of(cell);
      if (law == nullptr) continue;
      fev.reinit(cell);
      fev[displacement].get_function_gradients(solution_ghosted_, grad_u);
      auto& history = viscous_history_[cell->active_cell_index()];
      for (unsigned q = 0; q < grad_u.size(); ++q)
        law->commit(right_cauchy_green(unit_symmetric_tensor<3>() + grad_u[q]), time_step_s_, history[q]);
    }
  }
  time_step_s_ = 0.0;
}

void FiniteStrainSolver::restore(const Snapshot& snapshot) {
  solution_ = snapshot.solution;
  last_increment_ = snapshot.last_increment;
  viscous_history_ = snapshot.viscous_history;
  time_step_s_ = snapshot.time_step_s;
  solution_ghosted_ = solution_;
  assemble(solution_ghosted_, false, nullptr);
}

void FiniteStrainSolver::set_anchor_springs(const std::map<types::global_dof_index, double>& stiffness_N_per_m) {
  anchors_.clear();
  for (const auto& [dof, k] : stiffness_N_per_m) {
    if (!(k >= 0.0) || !std::isfinite(k))
      throw std::invalid_argument("FiniteStrainSolver: anchor spring stiffness must be finite and >= 0");
    if (locally_owned_.is_element(dof)) anchors_[dof] = {k, solution_[dof]};
  }
  anchor_scale_ = 1.0;
}

void FiniteStrainSolver::set_anchor_spring_scale(double scale) {
  if (!(scale >= 0.0) || !std::isfinite(scale))
    throw std::invalid_argument("FiniteStrainSolver: anchor spring scale must be finite and >= 0");
  anchor_scale_ = scale;
}

void FiniteStrainSolver::set_released_force_fraction(double fraction) {
  if (!(fraction >= 0.0 && fraction <= 1.0))
    throw std::invalid_argument("FiniteStrainSolver: released force fraction must lie in [0, 1]");
  released_fraction_ = fraction;
}

bool FiniteStrainSolver::is_removed(const CellIterator& cell) const {
  return removed_[cell->active_cell_index()] != 0;
}

void FiniteStrainSolver::increment_constraints(const TrilinosWrappers::MPI::Vector& u,
                                               AffineConstraints<double>& constraints) const {
  constraints.clear();
  constraints.reinit(locally_relevant_);
  for (const auto& [dof, target] : targets_)
    if (locally_relevant_.is_element(dof)) {
      constraints.add_line(dof);
      constraints.set_inhomogeneity(dof, target - u[dof]);
    }
  constraints.close();
}

double FiniteStrainSolver::free_residual_norm() const {
  TrilinosWrappers::MPI::Vector r(residual_);
  for (const auto& [dof, target] : targets_)
    if (locally_owned_.is_element(dof)) r[dof] = 0.0;
  r.compress(VectorOperation::insert);
  return r.l2_norm();
}

double FiniteStrainSolver::free_residual_dot(const TrilinosWrappers::MPI::Vector& du) const {
  TrilinosWrappers::MPI::Vector r(residual_);
  for (const auto& [dof, target] : targets_)
    if (locally_owned_.is_element(dof)) r[dof] = 0.0;
  r.compress(VectorOperation::insert);
  return r * du;
}

double FiniteStrainSolver::reaction_norm() const {
  double s = 0.0;
  for (const auto& [dof, target] : targets_)
    if (locally_owned_.is_element(dof)) s += residual_[dof] * residual_[dof];
  return std::sqrt(Utilities::MPI::sum(s, mpi_communicator()));
}

double FiniteStrainSolver::external_load_norm() const {
  // Dead loads only: |f_ext| from the traction resultants (upper bound of the
  // nodal load norm's scale, enough for a convergence scale).
  if (tractions_.empty()) return 0.0;
  const QGauss<2> face_quadrature(settings_.degree + 1);
  FEFaceValues<3> fefv(fe_, face_quadrature, update_JxW_values);
  double s = 0.0;
  for (const auto& cell : dof_handler_.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    for (unsigned f = 0; f < cell->n_faces(); ++f) {
      if (!cell->face(f)->at_boundary()) continue;
      const auto it = tractions_.find(cell->face(f)->boundary_id());
      if (it == tractions_.end()) continue;
      fefv.reinit(cell, f);
      for (unsigned q = 0; q < fefv.n_quadrature_points; ++q) s += it->second.norm() * fefv.JxW(q);
    }
  }
  return Utilities::MPI::sum(s, mpi_communicator());
}

double FiniteStrainSolver::max_constraint_gap() const {
  double gap = 0.0;
  for (const auto& [dof, target] : targets_)
    if (locally_owned_.is_element(dof)) gap = std::max(gap, std::abs(target - solution_[dof]));
  return Utilities::MPI::max(gap, mpi_communicator());
}

void FiniteStrainSolver::build_preconditioner() {
  // Smoothed-aggregation AMG (ML) with the six rigid-body modes of 3D
  // elasticity as near null space (translations and rotations evaluated at
  // the support points of the locally owned dofs). No aggregation
  // threshold: measured on the default slab, dropping weak connections
  // (0.02-0.1) made neither the setup nor the CG cheaper.
  amg_ = std::make_unique<TrilinosWrappers::PreconditionAMG>();
  TrilinosWrappers::PreconditionAMG::AdditionalData data;
  data.elliptic = true;
  data.higher_order_elements = settings_.degree > 1;
  data.smoother_sweeps = 2;
  data.aggregation_threshold = 0.0;
  Teuchos::ParameterList parameters;
  std::unique_ptr<Epetra_MultiVector> unused_modes;
  data.set_parameters(parameters, unused_modes, tangent_);
  const Epetra_Map& map = tangent_.trilinos_matrix().DomainMap();
  Epetra_MultiVector rigid_body_modes(map, 6);
  const int n_local = map.NumMyElements();
  for (int li = 0; li < n_local; ++li) {
    const types::global_dof_index dof = map.GID(li);
    const auto it = owned_support_.find(dof);
    if (it == owned_support_.end()) continue;
    const unsigned c = it->second.first;
    const Point<3>& X = it->second.second;
    rigid_body_modes[c][li] = 1.0;  // translations
    // rotations about x, y, z: (0,-z,y), (z,0,-x), (-y,x,0)
    const double rot[3][3] = {{0.0, -X[2], X[1]}, {X[2], 0.0, -X[0]}, {-X[1], X[0], 0.0}};
    for (unsigned r = 0; r < 3; ++r) rigid_body_modes[3 + r][li] = rot[r][c];
  }
  parameters.set("null space: type", "pre-computed");
  parameters.set("null space: dimension", 6);
  parameters.set("null space: vectors", rigid_body_modes.Values());
  amg_->initialize(tangent_, parameters);
}

unsigned int FiniteStrainSolver::solve_linear(TrilinosWrappers::MPI::Vector& du, double absolute_tolerance,
                                              bool rebuild_preconditioner) {
  TimerOutput::Scope section(timer_, "linear solve");
  du = 0.0;
  const double rhs_norm = rhs_.l2_norm();
  if (rhs_norm == 0.0) return 0;
  if (!settings_.direct_linear_solver) {
    SolverControl control(std::max<unsigned>(2000, 10 * std::sqrt(double(n_dofs()))),
                          std::max(settings_.linear_relative_tolerance * rhs_norm, absolute_tolerance));
    if (rebuild_preconditioner || !amg_) build_preconditioner();
    const TrilinosWrappers::PreconditionAMG& amg = *amg_;
    try {
      SolverCG<TrilinosWrappers::MPI::Vector> cg(control);
      cg.solve(tangent_, du, rhs_, amg);
      return control.last_step();
    } catch (const SolverControl::NoConvergence&) {
      // The tangent may be indefinite near a limit point: fall back below.
    }
    du = 0.0;
    try {
      SolverControl control2(control.max_steps(), control.tolerance());
      SolverGMRES<TrilinosWrappers::MPI::Vector> gmres(
          control2, SolverGMRES<TrilinosWrappers::MPI::Vector>::AdditionalData(100));
      gmres.solve(tangent_, du, rhs_, amg);
      return control2.last_step();
    } catch (const SolverControl::NoConvergence&) {
    }
    du = 0.0;
  }
  // Sparse direct solve (MUMPS through Amesos; KLU if MUMPS is missing).
  SolverControl control(1, 0);
  try {
    TrilinosWrappers::SolverDirect direct(control,
                                          TrilinosWrappers::SolverDirect::AdditionalData(false, "Amesos_Mumps"));
    direct.solve(tangent_, du, rhs_);
  } catch (const std::exception& e) {
    static bool warned = false;
    if (!warned && Utilities::MPI::this_mpi_process(mpi_communicator()) == 0)
      std::cerr << "fem: MUMPS direct solver failed (" << e.what() << "); using KLU" << std::endl;
    warned = true;
    du = 0.0;
    TrilinosWrappers::SolverDirect direct(control);
    direct.solve(tangent_, du, rhs_);
  }
  return 1;
}

/// What the phases of one solve_step share.
struct FiniteStrainSolver::Step {
  NewtonReport report;
  TrilinosWrappers::MPI::Vector u_start;        ///< the last converged solution (restored on failure)
  TrilinosWrappers::MPI::Vector du, trial;      ///< Newton direction; the line search's state (owned)
  TrilinosWrappers::MPI::Vector trial_ghosted;  ///< the line search's state (ghosted)
  AffineConstraints<double> constraints;        ///< the increment's constraints at solution_
  AffineConstraints<double> trial_constraints;  ///< and at the line search's full step
  double gap_tolerance_m = 0.0;  ///< prescribed displacement gap counted as closed
  double max_free = 0.0;         ///< largest free residual of the step so far (N)
  int stalled = 0;               ///< consecutive iterations with a short line-search step
  bool assembled_here = false;   ///< tangent, rhs and residual are those of solution_
};

/// One Newton iterate (the state solution_).
struct FiniteStrainSolver::Iterate {
  int it = 0;
  double free = 0.0;   ///< free residual (N)
  double gap = 0.0;    ///< largest prescribed displacement not yet reached (m)
  double scale = 0.0;  ///< force scale of the convergence test (N)
  bool converged = false;
  unsigned linear_iterations = 0;
  double assemble_s = 0.0, solve_s = 0.0;
  std::ostringstream line;  ///< the iterate's line of the Newton log
};

NewtonReport FiniteStrainSolver::solve_step(double predictor_scale) {
  if (!(predictor_scale >= 0.0) || !std::isfinite(predictor_scale))
    throw std::invalid_argument("FiniteStrainSolver::solve_step: predictor_scale must be finite and >= 0");
  Step step;
  start_step(step, predictor_scale);
  for (int it = 0;; ++it) {
    Iterate x;
    x.it = it;
    if (const Failure why = evaluate_iterate(step, x)) return fail_step(step, *why);
    if (x.converged) return accept_step(step, x);
    if (it >= settings_.max_newton_iterations) {
      step.report.table.push_back(x.line.str());
      step.report.iterations = it;
      return fail_step(step, "no convergence in " + std::to_string(it) + " Newton iterations");
    }
    if (const Failure why = newton_direction(step, x)) return fail_step(step, *why);
    double alpha = 0.0;
    if (const Failure why = line_search(step, x, alpha)) return fail_step(step, *why);
    step.stalled = alpha <= 0.125 ? step.stalled + 1 : 0;
    x.line << "  lin_its " << x.linear_iterations << "  alpha " << std::defaultfloat << alpha << "  t_assemble "
           << std::setprecision(3) << x.assemble_s << " s  t_solve " << x.solve_s << " s";
    step.report.table.push_back(x.line.str());
    print_verbose(step.report.table.back());
    solution_ = step.trial;
    solution_ghosted_ = solution_;
    if (settings_.max_stalled_iterations > 0 && step.stalled >= settings_.max_stalled_iterations) {
      step.report.iterations = it + 1;
      return fail_step(step, "stalled: " + std::to_string(step.stalled) +
                                 " iterations in a row with a line-search step <= 1/8");
    }
  }
}

void FiniteStrainSolver::start_step(Step& step, double predictor_scale) {
  const MPI_Comm comm = mpi_communicator();
  step.u_start = solution_;
  if (predictor_scale > 0.0 && last_increment_.linfty_norm() > 0.0) {
    // Extrapolated start; kept only if no element inverts.
    solution_.add(predictor_scale, last_increment_);
    solution_ghosted_ = solution_;
    if (assemble(solution_ghosted_, false, nullptr).valid) {
      step.report.table.push_back("     predictor: u + " + std::to_string(predictor_scale) + " x last increment");
    } else {
      solution_ = step.u_start;
      solution_ghosted_ = solution_;
    }
  }
  step.du.reinit(locally_owned_, comm);
  step.trial.reinit(locally_owned_, comm);
  step.trial_ghosted.reinit(locally_owned_, locally_relevant_, comm);
  double target_scale = 1e-12;
  for (const auto& [dof, t] : targets_) target_scale = std::max(target_scale, std::abs(t));
  step.gap_tolerance_m = 1e-12 * Utilities::MPI::max(target_scale, comm);
}

FiniteStrainSolver::Failure FiniteStrainSolver::evaluate_iterate(Step& step, Iterate& x) {
  increment_constraints(solution_ghosted_, step.constraints);
  const double assemble_before_s = section_wall_seconds(timer_, "assemble");
  // The full step of the last line search already assembled the tangent here.
  const bool assembled_valid = step.assembled_here || assemble(solution_ghosted_, true, &step.constraints).valid;
  step.assembled_here = false;
  x.assemble_s = section_wall_seconds(timer_, "assemble") - assemble_before_s;
  if (!assembled_valid) return "inverted or non-finite state at the start of an iteration";
  x.free = free_residual_norm();
  x.gap = max_constraint_gap();
  step.max_free = std::max(step.max_free, x.free);
  x.scale = std::max({reaction_norm(), external_load_norm(), step.max_free});
  step.report.residual_N = x.free;
  step.report.force_scale_N = x.scale;
  if (!std::isfinite(x.free)) return "non-finite residual";
  x.converged = x.gap <= step.gap_tolerance_m && (x.free <= settings_.newton_tolerance * x.scale ||
                                                  x.free <= settings_.absolute_residual_floor_N);
  x.line << std::setw(4) << x.it << "  |R_free| " << std::scientific << std::setprecision(3) << x.free
         << " N  |R_free|/scale " << (x.scale > 0 ? x.free / x.scale : 0.0) << "  gap " << x.gap << " m";
  return std::nullopt;
}

FiniteStrainSolver::Failure FiniteStrainSolver::newton_direction(Step& step, Iterate& x) {
  // K du = -R by CG + AMG (or a direct solver) to a tenth of the Newton target;
  // the AMG is rebuilt at the step's first iteration.
  const double newton_target =
      std::max(settings_.newton_tolerance * x.scale, settings_.absolute_residual_floor_N);
  const double solve_before_s = section_wall_seconds(timer_, "linear solve");
  x.linear_iterations =
      solve_linear(step.du, 0.1 * newton_target, x.it == 0 || settings_.rebuild_preconditioner_every_iteration);
  x.solve_s = section_wall_seconds(timer_, "linear solve") - solve_before_s;
  step.report.linear_iterations += x.linear_iterations;
  step.constraints.distribute(step.du);
  if (!std::isfinite(step.du.l2_norm())) return "non-finite Newton update";
  return std::nullopt;
}

FiniteStrainSolver::Failure FiniteStrainSolver::line_search(Step& step, Iterate& x, double& alpha) {
  // Any admissible step while a prescribed displacement is still being reached.
  std::ostringstream trials;
  trials << std::defaultfloat;
  const double slope0 = free_residual_dot(step.du);  // residual_ is the iterate's here
  const LineSearchResult search = backtracking_line_search(
      x.free, x.gap > step.gap_tolerance_m, settings_.absolute_residual_floor_N, settings_.max_line_search_halvings,
      [&](double a, int halvings) -> std::optional<double> {
        step.trial = solution_;
        step.trial.add(a, step.du);
        step.trial_ghosted = step.trial;
        // The full step is evaluated with the tangent: when it is accepted (the
        // common case) the next iteration needs no assembly of its own.
        const bool full_step = halvings == 0;
        if (full_step) increment_constraints(step.trial_ghosted, step.trial_constraints);
        if (!assemble(step.trial_ghosted, full_step, full_step ? &step.trial_constraints : nullptr).valid) {
          trials << ' ' << a << ":inverted";
          return std::nullopt;
        }
        const double free_N = free_residual_norm();
        trials << ' ' << a << ':' << std::setprecision(3) << free_N / x.free;
        return free_N;
      });
  alpha = search.alpha;
  // The log says why a step was cut: each rejected trial's alpha and its
  // residual relative to the iterate's (or "inverted" for an inadmissible
  // state); after "energy", the fallback's trials and their slope over |slope0|.
  const bool prescribing = x.gap > step.gap_tolerance_m;
  if (settings_.energy_line_search_fallback && !prescribing && alpha <= 0.125 && slope0 < 0.0) {
    trials << "  energy";
    const std::optional<double> a =
        energy_line_search(slope0, 8, [&](double a_trial) -> std::optional<double> {
          step.trial = solution_;
          step.trial.add(a_trial, step.du);
          step.trial_ghosted = step.trial;
          if (!assemble(step.trial_ghosted, false, nullptr).valid) {
            trials << ' ' << a_trial << ":inverted";
            return std::nullopt;
          }
          const double g = free_residual_dot(step.du);
          trials << ' ' << a_trial << ':' << std::setprecision(3) << g / -slope0;
          return g;
        });
    if (a && *a > alpha) {
      x.line << "  trials" << trials.str();
      alpha = *a;
      step.assembled_here = false;
      step.trial = solution_;
      step.trial.add(alpha, step.du);
      return std::nullopt;
    }
    if (alpha >= 0.0) {  // the fallback's trials overwrote the trial state: the backtracking's step again
      step.trial = solution_;
      step.trial.add(alpha, step.du);
    }
  }
  if (search.halvings > 0 || !search.accepted) x.line << "  trials" << trials.str();
  if (search.accepted) {
    step.assembled_here = search.halvings == 0;
    return std::nullopt;
  }
  if (alpha < 0.0) return "line search: every trial state has inverted elements";
  // No decrease found: the least bad admissible step.
  step.trial = solution_;
  step.trial.add(alpha, step.du);
  return std::nullopt;
}

NewtonReport FiniteStrainSolver::accept_step(Step& step, const Iterate& x) {
  step.report.table.push_back(x.line.str() + "  converged");
  print_verbose(step.report.table.back());
  step.report.converged = true;
  step.report.iterations = x.it;
  last_increment_ = solution_;
  last_increment_ -= step.u_start;
  return step.report;
}

NewtonReport FiniteStrainSolver::fail_step(Step& step, const std::string& why) {
  solution_ = step.u_start;
  solution_ghosted_ = solution_;
  assemble(solution_ghosted_, false, nullptr);
  step.report.converged = false;
  step.report.failure = why;
  print_verbose("newton failed: " + why);
  return step.report;
}

void FiniteStrainSolver::print_verbose(const std::string& line) const {
  if (settings_.verbose && Utilities::MPI::this_mpi_process(mpi_communicator()) == 0)
    std::cout << "      " << line << std::endl;
}

double FiniteStrainSolver::sum_of_residual(const std::vector<types::global_dof_index>& dofs) const {
  const std::set<types::global_dof_index> unique(dofs.begin(), dofs.end());
  double s = 0.0;
  for (const auto dof : unique)
    if (locally_owned_.is_element(dof)) s += residual_[dof];
  return Utilities::MPI::sum(s, mpi_communicator());
}

double FiniteStrainSolver::max_principal_stretch(
    const std::function<bool(const CellIterator&)>& predicate) const {
  const QGauss<3> quadrature(settings_.degree + 1);
  FEValues<3> fev(fe_, quadrature, update_gradients);
  const FEValuesExtractors::Vector displacement(0);
  std::vector<Tensor<2, 3>> grad_u(quadrature.size());
  double stretch = 1.0;
  for (const auto& cell : dof_handler_.active_cell_iterators()) {
    if (!cell->is_locally_owned() || is_removed(cell) || !predicate(cell)) continue;
    fev.reinit(cell);
    fev[displacement].get_function_gradients(solution_ghosted_, grad_u);
    for (const auto& g : grad_u) {
      const Tensor<2, 3> F = unit_symmetric_tensor<3>() + g;
      const auto ev = eigenvalues(right_cauchy_green(F));
      stretch = std::max(stretch, std::sqrt(std::max(ev[0], 0.0)));
    }
  }
  return Utilities::MPI::max(stretch, mpi_communicator());
}

}  // namespace puncture::fem
