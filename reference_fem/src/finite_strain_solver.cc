// finite_strain_solver.cc: see finite_strain_solver.hpp for the formulation.
#include <puncture/fem/finite_strain_solver.hpp>
#include <puncture/fem/kinematics.hpp>

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
#include <chrono>
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

void FiniteStrainSolver::restore(const Snapshot& snapshot) {
  solution_ = snapshot.solution;
  last_increment_ = snapshot.last_increment;
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

NewtonReport FiniteStrainSolver::solve_step(double predictor_scale) {
  NewtonReport report;
  const MPI_Comm comm = mpi_communicator();
  const bool root = Utilities::MPI::this_mpi_process(comm) == 0;
  const TrilinosWrappers::MPI::Vector u_start(solution_);
  if (!(predictor_scale >= 0.0) || !std::isfinite(predictor_scale))
    throw std::invalid_argument("FiniteStrainSolver::solve_step: predictor_scale must be finite and >= 0");
  bool predicted = false;
  if (predictor_scale > 0.0 && last_increment_.linfty_norm() > 0.0) {
    // Extrapolated start; kept only if no element inverts.
    solution_.add(predictor_scale, last_increment_);
    solution_ghosted_ = solution_;
    predicted = assemble(solution_ghosted_, false, nullptr).valid;
    if (!predicted) {
      solution_ = u_start;
      solution_ghosted_ = solution_;
    }
  }
  if (predicted) report.table.push_back("     predictor: u + " + std::to_string(predictor_scale) + " x last increment");
  TrilinosWrappers::MPI::Vector du(locally_owned_, comm), trial(locally_owned_, comm);
  TrilinosWrappers::MPI::Vector trial_ghosted(locally_owned_, locally_relevant_, comm);
  double max_free = 0.0;
  double target_scale = 1e-12;
  for (const auto& [dof, t] : targets_) target_scale = std::max(target_scale, std::abs(t));
  target_scale = Utilities::MPI::max(target_scale, comm);
  const double gap_tolerance = 1e-12 * target_scale;

  auto fail = [&](const std::string& why) {
    solution_ = u_start;
    solution_ghosted_ = solution_;
    assemble(solution_ghosted_, false, nullptr);
    report.converged = false;
    report.failure = why;
    if (settings_.verbose && root) std::cout << "      newton failed: " << why << std::endl;
    return report;
  };

  int stalled = 0;  // consecutive iterations with a short line-search step
  bool assembled_here = false;  // tangent, rhs and residual are those of the current state
  AffineConstraints<double> constraints, trial_constraints;
  for (int it = 0;; ++it) {
    increment_constraints(solution_ghosted_, constraints);
    const auto t_assemble = std::chrono::steady_clock::now();
    // The full step of the last line search already assembled the tangent here.
    const bool assembled_valid = assembled_here || assemble(solution_ghosted_, true, &constraints).valid;
    assembled_here = false;
    const double assemble_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t_assemble).count();
    if (!assembled_valid)
      return fail("inverted or non-finite state at the start of an iteration");
    const double free = free_residual_norm();
    const double gap = max_constraint_gap();
    max_free = std::max(max_free, free);
    const double scale = std::max({reaction_norm(), external_load_norm(), max_free});
    report.residual_N = free;
    report.force_scale_N = scale;
    if (!std::isfinite(free)) return fail("non-finite residual");
    const bool converged =
        gap <= gap_tolerance &&
        (free <= settings_.newton_tolerance * scale || free <= settings_.absolute_residual_floor_N);
    std::ostringstream line;
    line << std::setw(4) << it << "  |R_free| " << std::scientific << std::setprecision(3) << free
         << " N  |R_free|/scale " << (scale > 0 ? free / scale : 0.0) << "  gap " << gap << " m";
    if (converged) {
      report.table.push_back(line.str() + "  converged");
      if (settings_.verbose && root) std::cout << "      " << report.table.back() << std::endl;
      report.converged = true;
      report.iterations = it;
      last_increment_ = solution_;
      last_increment_ -= u_start;
      return report;
    }
    if (it >= settings_.max_newton_iterations) {
      report.table.push_back(line.str());
      report.iterations = it;
      return fail("no convergence in " + std::to_string(it) + " Newton iterations");
    }
    const auto t_solve = std::chrono::steady_clock::now();
    const double newton_target =
        std::max(settings_.newton_tolerance * scale, settings_.absolute_residual_floor_N);
    const unsigned lin_its =
        solve_linear(du, 0.1 * newton_target, it == 0 || settings_.rebuild_preconditioner_every_iteration);
    const double solve_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_solve).count();
    report.linear_iterations += lin_its;
    constraints.distribute(du);
    if (!std::isfinite(du.l2_norm())) return fail("non-finite Newton update");

    // Backtracking line search.
    double alpha = 1.0, best_alpha = -1.0, best_free = std::numeric_limits<double>::infinity();
    bool accepted = false;
    for (int h = 0; h <= settings_.max_line_search_halvings; ++h, alpha *= 0.5) {
      trial = solution_;
      trial.add(alpha, du);
      trial_ghosted = trial;
      // The full step is evaluated with the tangent: when it is accepted (the
      // common case) the next iteration needs no assembly of its own.
      const bool full_step = h == 0;
      if (full_step) increment_constraints(trial_ghosted, trial_constraints);
      if (!assemble(trial_ghosted, full_step, full_step ? &trial_constraints : nullptr).valid) continue;
      const double trial_free = free_residual_norm();
      if (!std::isfinite(trial_free)) continue;
      if (gap > gap_tolerance || trial_free < (1.0 - 1e-4 * alpha) * free ||
          trial_free <= settings_.absolute_residual_floor_N) {
        accepted = true;
        assembled_here = full_step;
        break;
      }
      if (trial_free < best_free) {
        best_free = trial_free;
        best_alpha = alpha;
      }
    }
    if (!accepted) {
      if (best_alpha < 0.0) return fail("line search: every trial state has inverted elements");
      alpha = best_alpha;  // no decrease found: take the least bad admissible step
      trial = solution_;
      trial.add(alpha, du);
    }
    stalled = alpha <= 0.125 ? stalled + 1 : 0;
    line << "  lin_its " << lin_its << "  alpha " << std::defaultfloat << alpha << "  t_assemble "
         << std::setprecision(3) << assemble_s << " s  t_solve " << solve_s << " s";
    report.table.push_back(line.str());
    if (settings_.verbose && root) std::cout << "      " << report.table.back() << std::endl;
    solution_ = trial;
    solution_ghosted_ = solution_;
    if (settings_.max_stalled_iterations > 0 && stalled >= settings_.max_stalled_iterations) {
      report.iterations = it + 1;
      return fail("stalled: " + std::to_string(stalled) + " iterations in a row with a line-search step <= 1/8");
    }
  }
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
