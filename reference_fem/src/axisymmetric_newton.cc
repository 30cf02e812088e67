// axisymmetric_newton.cc: one load step of the AxisymmetricSolver read as the algorithm:
// start the step, evaluate an iterate, update the punch contact, Newton direction, line
// search, accept or fail (axisymmetric_solver.hpp).
#include <puncture/fem/axisymmetric_solver.hpp>
#include <puncture/fem/kinematics.hpp>

#include <deal.II/base/function.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_direct.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <iomanip>
#include <exception>
#include <iostream>
#include <thread>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "axisymmetric_cell.hpp"
#include "backtracking_line_search.hpp"
#include "solver_timing.hpp"

namespace puncture::fem {
using namespace dealii;
using namespace axisymmetric_cell;

namespace {
/// The predictor is kept unless its free residual exceeds this factor times
/// the residual without it.
constexpr double kPredictorResidualFactor = 10.0;
/// A line search that finds no decrease takes its least bad step, unless that
/// raises the residual beyond this factor (the Newton solve fails instead).
constexpr double kUphillLimit = 10.0;
}  // namespace

/// What the phases of one solve_step share.
struct AxisymmetricSolver::Step {
  AxisymmetricNewtonReport report;
  Vector<double> u_start;                 ///< the last converged solution (restored on failure)
  std::vector<char> punch_contact_start;  ///< the flat punch's contact set at the start
  std::vector<double> punch_hold_start;   ///< and its held u_R
  std::vector<char> released_in_step;     ///< punch nodes released for a tensile reaction (free for the step)
  AffineConstraints<double> constraints;  ///< the Newton increment's constraints at solution_
  SparseDirectUMFPACK direct;
  Vector<double> du, trial;               ///< Newton direction; the line search's state
  double max_free = 0.0;                  ///< largest free residual of the step so far (N)
  int contact_changes = 0;                ///< changes of the punch contact set so far
  std::vector<double> history;            ///< free residual per iteration of one Newton solve (stall detection)
  bool strict = false;                    ///< converged to the Newton tolerance (not only at a stall)
  /// The line search's accepted trial was assembled with its tangent (the first
  /// trial, alpha = 1, is): the next iterate is that state, already assembled.
  bool assembled_at_solution = false;
  bool trial_has_tangent = false;         ///< the last trial state was assembled with its tangent
  double trial_assemble_s = 0.0;          ///< wall time of that assembly (s)
};

/// One Newton iterate (the state solution_).
struct AxisymmetricSolver::Iterate {
  double free = 0.0;   ///< free residual (N)
  double gap = 0.0;    ///< largest prescribed punch displacement not yet reached (m)
  double scale = 0.0;  ///< force scale of the convergence test (N)
  bool stalled = false, strict = false, converged = false;
  double assemble_s = 0.0, solve_s = 0.0;
  double direction_tip_elements = 0.0;  ///< the Newton direction's largest nodal move, in tip elements (before the cap)
  std::ostringstream line;  ///< the iterate's line of the Newton log
};

AxisymmetricNewtonReport AxisymmetricSolver::solve_step(double predictor_scale, bool continue_if_stuck) {
  Step step;
  start_step(step, predictor_scale);
  Failure why = newton(step, settings_.max_newton_iterations);
  if (why && continue_if_stuck && settings_.continuation_steps > 0) why = continue_step(step, *why);
  return why ? fail_step(step, *why) : accept_step(step);
}

AxisymmetricSolver::Failure AxisymmetricSolver::newton(Step& step, int max_iterations) {
  step.history.clear();
  step.max_free = 0.0;
  step.contact_changes = 0;
  step.assembled_at_solution = false;
  for (int it = 0;; ++it) {
    Iterate x;
    if (const Failure why = evaluate_iterate(step, it, x)) return why;
    if (x.converged) {
      // Flat punch: release nodes pulled by the face (tensile reaction) and
      // take in the nodes it reaches; if the contact set changed, go on.
      const bool released = release_pulled_punch_nodes(step.released_in_step, x.scale);
      const bool joined = update_punch_contact(step.released_in_step);
      if (!released && !joined) {
        step.strict = x.strict;
        step.report.iterations += it;
        step.report.table.push_back(x.line.str() +
                                    (x.strict ? "  converged" : "  converged (stalled below the acceptance tolerance)"));
        if (settings_.verbose) std::cout << "      " << step.report.table.back() << std::endl;
        return std::nullopt;
      }
      if (++step.contact_changes > 50) return "flat punch contact set does not settle";
      x.line << "  (punch contact set changed)";
      step.report.table.push_back(x.line.str());
      continue;
    }
    if (const Failure why = give_up_reason(it, x, max_iterations)) {
      step.report.table.push_back(x.line.str());
      step.report.iterations += it;
      return why;
    }
    if (const Failure why = newton_direction(step, x)) return why;
    if (std::getenv("PUNCTURE_FEM_CHECK_TANGENT") != nullptr && it > 0) x.line << "  " << tangent_check(step, step.du);
    double alpha = 0.0;
    if (const Failure why = line_search(step, x, alpha)) return why;
    x.line << "  du/h " << std::defaultfloat << std::setprecision(3) << x.direction_tip_elements << "  alpha "
           << alpha << "  t_assemble " << std::setprecision(3) << x.assemble_s
           << " s  t_solve " << x.solve_s << " s";
    step.report.table.push_back(x.line.str());
    if (settings_.verbose) std::cout << "      " << step.report.table.back() << std::endl;
    solution_ = step.trial;
  }
}

// Pseudo-transient continuation (Kelley & Keyes 1998; Coffey, Kelley & Keyes
// 2003) of a step plain Newton could not solve: from the step's start, a
// sequence of pseudo-time steps at the same needle position, each the step's
// equations plus a viscous stress ratio 2 mu_0 sym(H - H_k) on the change
// from the previous pseudo-step's state H_k. A large ratio makes each
// pseudo-step an easy, nearly linear solve (the tissue may only creep toward
// equilibrium); the ratio falls by continuation_decrease after each converged
// pseudo-step and rises by continuation_increase (the pseudo-step undone)
// after a failed one. Once it is below continuation_final_ratio the viscous
// stress is negligible and plain Newton finishes the step from there: the
// accepted state solves the step's own equations, continuation only finds it.
// Where that policy gives up, a slower one (continuation_retry_*: ratio
// halved per converged pseudo-step, many more pseudo-steps) starts again from
// the step's start: an equilibrium far away is reached in small moves.
AxisymmetricSolver::Failure AxisymmetricSolver::continue_step(Step& step, const std::string& plain_failure) {
  std::ostringstream head;
  head << "  -> " << plain_failure << "; pseudo-transient continuation";
  step.report.table.push_back(head.str());
  bool reached = pseudo_transient(step, settings_.continuation_steps, settings_.continuation_max_failures,
                                  settings_.continuation_decrease, settings_.continuation_increase);
  if (!reached && settings_.continuation_retry_steps > 0) {
    step.report.table.push_back("  -> the slower continuation (retry policy)");
    reached = pseudo_transient(step, settings_.continuation_retry_steps, settings_.continuation_retry_max_failures,
                               settings_.continuation_retry_decrease, settings_.continuation_retry_increase);
  }
  continuation_ratio_ = 0.0;
  ++step.report.continuation_steps;
  if (!reached) return plain_failure + "; pseudo-transient continuation did not reach the step's equilibrium either";
  step.report.table.push_back("  plain Newton from the continued state");
  if (const Failure why = newton(step, settings_.max_newton_iterations))
    return plain_failure + "; after pseudo-transient continuation: " + *why;
  return std::nullopt;
}

bool AxisymmetricSolver::pseudo_transient(Step& step, int steps, int max_failures, double decrease, double increase) {
  restore_step_start(step);
  double ratio = settings_.continuation_initial_ratio;
  int failures = 0;
  for (int k = 0; k < steps && ratio >= settings_.continuation_final_ratio; ++k) {
    continuation_reference_ = solution_;
    continuation_ratio_ = ratio;
    const Failure why = newton(step, settings_.continuation_max_iterations);
    std::ostringstream line;
    line << "  pseudo-step " << k << "  ratio " << std::scientific << std::setprecision(2) << ratio << "  "
         << (why ? "failed: " + *why : std::string("converged"));
    step.report.table.push_back(line.str());
    if (settings_.verbose) std::cout << "      " << line.str() << std::endl;
    if (why) {
      solution_ = continuation_reference_;
      if (++failures > max_failures) break;
      ratio *= increase;
    } else {
      ratio /= decrease;
    }
  }
  continuation_ratio_ = 0.0;
  return ratio < settings_.continuation_final_ratio;
}

void AxisymmetricSolver::start_step(Step& step, double predictor_scale) {
  step.u_start = solution_;
  step_start_ = step.u_start;
  step.punch_contact_start = punch_contact_;
  step.punch_hold_start = punch_lateral_hold_;
  if (predictor_scale > 0.0 && last_increment_.linfty_norm() > 0.0) {
    // The extrapolated start only where it is admissible and not far worse
    // than the last state (through a snap the last increment points the
    // wrong way, and its residual would inflate the step's force scale, the
    // convergence test). Not only where it is better: along a withdrawal
    // the extrapolated sliding is the better start although its first
    // residual is often larger.
    Vector<double> predicted = solution_;
    predicted.add(predictor_scale, last_increment_);
    if (free_residual_at(predicted) < kPredictorResidualFactor * free_residual_at(solution_)) solution_ = predicted;
  }
  step.released_in_step.assign(contact_nodes_.size(), 0);
  update_punch_contact(step.released_in_step);
  step.du.reinit(solution_.size());
  step.trial.reinit(solution_.size());
}

AxisymmetricSolver::Failure AxisymmetricSolver::evaluate_iterate(Step& step, int it, Iterate& x) {
  debug_contacts_ = settings_.verbose && std::getenv("PUNCTURE_FEM_DEBUG_CONTACT") != nullptr;
  make_constraints(solution_, step.constraints);
  if (step.assembled_at_solution && !debug_contacts_) {
    // The line search's first trial, accepted, is this state with its tangent:
    // residual, tangent and trial histories are those an assembly here gives.
    x.assemble_s = step.trial_assemble_s;
  } else {
    const double assemble_before_s = section_wall_seconds(timer_, "assemble");
    if (!assemble(solution_, true)) return "inverted or non-finite state";
    x.assemble_s = section_wall_seconds(timer_, "assemble") - assemble_before_s;
  }
  step.assembled_at_solution = false;
  debug_contacts_ = false;
  const AffineConstraints<double>& constraints = step.constraints;
  x.free = free_residual_norm(constraints);
  for (std::size_t i = 0; i < solution_.size(); ++i)
    if (constraints.is_inhomogeneously_constrained(i))
      x.gap = std::max(x.gap, std::abs(constraints.get_inhomogeneity(i)));
  step.max_free = std::max(step.max_free, x.free);
  double reaction = std::abs(force_trial_.total_N);
  for (std::size_t i = 0; i < solution_.size(); ++i)
    if (constraints.is_constrained(i)) reaction = std::max(reaction, std::abs(residual_(i)));
  x.scale = std::max({reaction, step.max_free, 1e-300});
  step.report.residual_N = x.free;
  step.report.force_scale_N = x.scale;
  if (!std::isfinite(x.free)) return "non-finite residual";
  x.stalled = check_stall(step.history, x.free);
  const bool gap_closed = x.gap <= 1e-12 * std::max(1e-3, punch_radius_m_);
  x.strict = x.free <= settings_.newton_tolerance * x.scale || x.free <= settings_.absolute_residual_floor_N;
  // A stall is accepted below stall_acceptance_tolerance x the force scale;
  // where the insertion set a floor (a share of the run's peak needle force),
  // below that floor instead, or below the tolerance x the current needle
  // force if larger: the force scale also holds the reactions at the crack
  // line's ties and supports, which can exceed the needle force a hundredfold,
  // and a residual accepted against them would be percents of the peak.
  const double stall_bound =
      stall_acceptance_floor_N_ > 0.0
          ? std::max(stall_acceptance_floor_N_,
                     settings_.stall_acceptance_tolerance * std::min(x.scale, std::abs(force_trial_.total_N)))
          : settings_.stall_acceptance_tolerance * x.scale;
  const bool loose = x.stalled && x.free <= stall_bound;
  x.converged = gap_closed && (x.strict || loose);
  write_iterate_line(it, x);
  return std::nullopt;
}

double AxisymmetricSolver::free_residual_at(const Vector<double>& u) {
  if (!assemble(u, false)) return std::numeric_limits<double>::infinity();
  AffineConstraints<double> c;
  make_constraints(u, c);
  const double r = free_residual_norm(c);
  return std::isfinite(r) ? r : std::numeric_limits<double>::infinity();
}

bool AxisymmetricSolver::check_stall(std::vector<double>& history, double free) const {
  // Stall: the best residual of the last stall_window iterations is not
  // below stall_factor x the best before them.
  history.push_back(free);
  const int window = settings_.stall_window;
  if (window <= 0 || static_cast<int>(history.size()) <= window) return false;
  const double before = *std::min_element(history.begin(), history.end() - window);
  const double recent = *std::min_element(history.end() - window, history.end());
  return recent > settings_.stall_factor * before;
}

void AxisymmetricSolver::write_iterate_line(int it, Iterate& x) const {
  int sliding = 0, damaged = 0, broken = 0, closed = 0;
  for (const auto& h : friction_trial_) sliding += h.sliding ? 1 : 0;
  for (std::size_t k = 0; k < cohesive_points_.size(); ++k) {
    damaged += cohesive_trial_[k].damage > 0.0 ? 1 : 0;
    broken += cohesive_trial_[k].damage >= 1.0 ? 1 : 0;
    closed += (cohesive_trial_[k].damage > 0.0 &&
               solution_(cohesive_points_[k].outer_r) < solution_(cohesive_points_[k].core_r)) ? 1 : 0;
  }
  x.line << std::setw(4) << it << "  |R_free| " << std::scientific << std::setprecision(3) << x.free << " N  scale "
         << x.scale << " N  F_needle " << force_trial_.total_N << " N  contact " << force_trial_.nodes_in_contact
         << " sliding " << sliding << " damaged " << damaged << " broken " << broken << " closed " << closed;
  // Switches of branch since the last logged iterate (kinks Newton crosses):
  // bit 1 of a cohesive point's branch is loading/unloading, bit 2 open/closed;
  // bit 1 of a contact node's is touching.
  int loading = 0, opening = 0, touching = 0;
  if (cohesive_branch_logged_.size() == cohesive_branch_.size())
    for (std::size_t k = 0; k < cohesive_branch_.size(); ++k) {
      const unsigned char changed = cohesive_branch_[k] ^ cohesive_branch_logged_[k];
      loading += (changed & 1) ? 1 : 0;
      opening += (changed & 2) ? 1 : 0;
    }
  if (contact_branch_logged_.size() == contact_branch_.size())
    for (std::size_t k = 0; k < contact_branch_.size(); ++k) touching += ((contact_branch_[k] ^ contact_branch_logged_[k]) & 1) ? 1 : 0;
  cohesive_branch_logged_ = cohesive_branch_;
  contact_branch_logged_ = contact_branch_;
  if (it > 0) x.line << "  switched: loading " << loading << " opening " << opening << " contact " << touching;
}

bool AxisymmetricSolver::release_pulled_punch_nodes(std::vector<char>& released_in_step, double scale) {
  bool released = false;
  if (cutting_) return released;
  for (std::size_t i = 0; i < contact_nodes_.size(); ++i) {
    if (!punch_contact_[i] || tied_slave(i)) continue;
    // A tied pair of crack nodes carries its reaction together.
    const int p = contact_nodes_[i].partner;
    double reaction = residual_(contact_nodes_[i].dof_z);
    if (p >= 0 && tied_slave(static_cast<std::size_t>(p))) reaction += residual_(contact_nodes_[p].dof_z);
    if (reaction > 1e-6 * scale) {  // R_z > 0: the face would pull the node
      if (settings_.verbose)
        std::cout << "      punch releases node R=" << contact_nodes_[i].R << " reaction " << reaction << std::endl;
      punch_contact_[i] = 0;
      released_in_step[i] = 1;
      if (p >= 0 && tied_slave(static_cast<std::size_t>(p))) punch_contact_[p] = 0;
      released = true;
    }
  }
  return released;
}

bool AxisymmetricSolver::update_punch_contact(const std::vector<char>& released_in_step) {
  // Flat punch: top nodes within the punch radius that the face has reached
  // join; a node released for a tensile reaction stays free for this step.
  bool changed = false;
  if (cutting_) return changed;
  for (std::size_t i = 0; i < contact_nodes_.size(); ++i) {
    const ContactNode& nd = contact_nodes_[i];
    if (punch_contact_[i] || released_in_step[i] || !nd.on_top || nd.R > punch_radius_m_ * (1 + 1e-9) ||
        tied_slave(i))
      continue;
    if (nd.Z + solution_(nd.dof_z) >= punch_z_m_) {
      punch_contact_[i] = 1;
      punch_lateral_hold_[i] = solution_(nd.dof_r);
      if (nd.partner >= 0 && tied_slave(static_cast<std::size_t>(nd.partner))) punch_contact_[nd.partner] = 1;
      changed = true;
    }
  }
  return changed;
}

AxisymmetricSolver::Failure AxisymmetricSolver::give_up_reason(int it, const Iterate& x, int max_iterations) const {
  if (it >= max_iterations) return "no convergence in " + std::to_string(it) + " Newton iterations";
  if (!x.stalled) return std::nullopt;
  std::ostringstream why;
  why << "Newton stalls: |R_free| " << std::scientific << std::setprecision(3) << x.free << " N did not fall by "
      << std::defaultfloat << 100.0 * (1.0 - settings_.stall_factor) << " % in " << settings_.stall_window
      << " iterations";
  return why.str();
}

AxisymmetricSolver::Failure AxisymmetricSolver::newton_direction(Step& step, Iterate& x) {
  // Linear system K du = -R with the increment constraints condensed in
  // (UMFPACK takes the nonsymmetric tangent of sliding friction).
  rhs_ = residual_;
  rhs_ *= -1.0;
  const double solve_before_s = section_wall_seconds(timer_, "linear solve");
  {
    TimerOutput::Scope section(timer_, "linear solve");
    system_matrix_.copy_from(tangent_);
    step.constraints.condense(system_matrix_, rhs_);
    try {
      step.direct.initialize(system_matrix_);
      step.direct.vmult(step.du, rhs_);
    } catch (const std::exception& e) {
      return std::string("sparse direct solve failed: ") + e.what();
    }
  }
  x.solve_s = section_wall_seconds(timer_, "linear solve") - solve_before_s;
  step.constraints.distribute(step.du);
  if (!std::isfinite(step.du.l2_norm())) return "non-finite Newton update";
  // Trust region on the displacement: no node moves more than
  // max_newton_displacement tip elements in one iteration, unless a
  // prescribed value asks for it (a node held only by a vanishing contact
  // stiffness would otherwise be thrown across the mesh by the full step).
  const double limit = settings_.max_newton_displacement * mesh_.tip_element_size_m;
  const double largest = step.du.linfty_norm();
  x.direction_tip_elements = largest / mesh_.tip_element_size_m;
  if (limit > 0.0 && largest > limit && x.gap <= 0.0) step.du *= limit / largest;
  return std::nullopt;
}

std::string AxisymmetricSolver::tangent_check(const Step& step, const Vector<double>& direction) {
  // K v against (R(u + e v) - R(u - e v)) / 2e on the free dofs, with e such
  // that the largest nodal move is 1e-4 tip elements.
  const double largest = direction.linfty_norm();
  if (!(largest > 0.0)) return "tangent check: no direction";
  const double eps = 1e-4 * mesh_.tip_element_size_m / largest;
  Vector<double> Kv(direction.size()), plus(direction.size()), minus(direction.size());
  tangent_.vmult(Kv, direction);
  const Vector<double> u = solution_;
  Vector<double> shifted = u;
  shifted.add(eps, direction);
  const bool ok_plus = assemble(shifted, false);
  plus = residual_;
  shifted = u;
  shifted.add(-eps, direction);
  const bool ok_minus = assemble(shifted, false);
  minus = residual_;
  assemble(u, true);  // the state, residual and tangent as they were
  if (!ok_plus || !ok_minus) return "tangent check: a shifted state is inadmissible";
  std::vector<char> kind(direction.size(), 0);  // 0 other, 1 contact node, 2 cohesive
  for (const ContactNode& n : contact_nodes_) kind[n.dof_r] = kind[n.dof_z] = 1;
  for (const CohesivePoint& c : cohesive_points_)
    for (unsigned d : {c.core_r, c.core_z, c.outer_r, c.outer_z})
      if (d < kind.size()) kind[d] = 2;
  double err[3] = {0.0, 0.0, 0.0}, ref[3] = {0.0, 0.0, 0.0}, worst = 0.0;
  std::size_t worst_dof = 0;
  for (std::size_t i = 0; i < direction.size(); ++i) {
    if (step.constraints.is_constrained(i)) continue;
    const double fd = (plus(i) - minus(i)) / (2.0 * eps);
    const double e = Kv(i) - fd;
    err[kind[i]] += e * e;
    ref[kind[i]] += fd * fd;
    if (std::abs(e) > worst) {
      worst = std::abs(e);
      worst_dof = i;
    }
  }
  std::ostringstream line;
  const double all_ref = std::sqrt(ref[0] + ref[1] + ref[2]);
  line << std::scientific << std::setprecision(2) << "tangent check |Kv - FD| / |FD|: all "
       << std::sqrt(err[0] + err[1] + err[2]) / all_ref << " (contact " << std::sqrt(err[1]) / all_ref << ", cohesive "
       << std::sqrt(err[2]) / all_ref << ", other " << std::sqrt(err[0]) / all_ref << "), worst dof " << worst_dof
       << " (" << (kind[worst_dof] == 1 ? "contact" : kind[worst_dof] == 2 ? "cohesive" : "other") << ")";
  return line.str();
}

AxisymmetricSolver::Failure AxisymmetricSolver::line_search(Step& step, const Iterate& x, double& alpha) {
  // Any admissible step while the punch gap closes. The first trial (the full
  // step, accepted in most iterations) is assembled with its tangent: accepted,
  // it is the next iterate's assembly; the shorter trials need the residual only.
  const LineSearchResult search = backtracking_line_search(
      x.free, x.gap > 0.0, settings_.absolute_residual_floor_N, settings_.max_line_search_halvings,
      [&](double a, int halvings) -> std::optional<double> {
        step.trial = solution_;
        step.trial.add(a, step.du);
        const bool with_matrix = halvings == 0;
        const double before_s = section_wall_seconds(timer_, "assemble");
        step.trial_has_tangent = false;
        if (!assemble(step.trial, with_matrix)) return std::nullopt;
        step.trial_has_tangent = with_matrix;
        if (with_matrix) step.trial_assemble_s = section_wall_seconds(timer_, "assemble") - before_s;
        AffineConstraints<double> tc;
        make_constraints(step.trial, tc);
        return free_residual_norm(tc);
      });
  alpha = search.alpha;
  step.assembled_at_solution = search.accepted && step.trial_has_tangent;
  if (search.accepted) return std::nullopt;
  if (alpha < 0.0) return "line search: every trial state is inverted or non-finite";
  // No decrease found: the least bad admissible step, unless it would throw
  // the iterate far from where it is (a near-singular direction at a kink).
  if (search.free_N > kUphillLimit * x.free)
    return "line search: every trial step multiplies the residual by more than " + std::to_string(int(kUphillLimit));
  step.trial = solution_;
  step.trial.add(alpha, step.du);
  return std::nullopt;
}

AxisymmetricNewtonReport AxisymmetricSolver::accept_step(Step& step) {
  AxisymmetricNewtonReport& report = step.report;
  report.accepted_at_stall = !step.strict;
  report.converged = true;
  last_increment_ = solution_;
  last_increment_ -= step.u_start;
  commit();
  update_penalties();
  return report;
}

void AxisymmetricSolver::restore_step_start(Step& step) {
  continuation_ratio_ = 0.0;
  solution_ = step.u_start;
  punch_contact_ = step.punch_contact_start;
  punch_lateral_hold_ = step.punch_hold_start;
  step.released_in_step.assign(contact_nodes_.size(), 0);
  cohesive_trial_ = cohesive_committed_;
  friction_trial_ = friction_committed_;
}

AxisymmetricNewtonReport AxisymmetricSolver::fail_step(Step& step, const std::string& why) {
  restore_step_start(step);
  assemble(solution_, true);
  step.report.converged = false;
  step.report.failure = why;
  if (settings_.verbose) std::cout << "      newton failed: " << why << std::endl;
  return step.report;
}

}  // namespace puncture::fem
