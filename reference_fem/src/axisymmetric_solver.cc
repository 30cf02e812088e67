// axisymmetric_solver.cc: see axisymmetric_solver.hpp for the formulation. This file: the
// viscoelastic history, constraints, assembly (cells, cohesive crack, needle contact),
// commit and snapshots; setup in axisymmetric_solver_setup.cc, the Newton step in
// axisymmetric_newton.cc.
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

namespace puncture::fem {
using namespace dealii;
using namespace axisymmetric_cell;

namespace {

/// Viscous stabilisation at one quadrature point: the stress two_mu_v sym(dH)
/// (dH the step's increment of the displacement gradient) against the test
/// gradients gradN: adds its forces to Re and, with_matrix, its stiffness to
/// the lower triangle of Ke. Returns its energy two_mu_v |sym(dH)|^2 dV (J).
double add_stabilization(double two_mu_v, const Tensor<2, 3>& dH, const std::vector<Tensor<2, 3>>& gradN,
                         double dV, bool with_matrix, FullMatrix<double>& Ke, Vector<double>& Re) {
  const Tensor<2, 3> eps = 0.5 * (dH + transpose(dH));
  for (unsigned i = 0; i < gradN.size(); ++i) {
    const Tensor<2, 3> ei = 0.5 * (gradN[i] + transpose(gradN[i]));
    Re(i) += two_mu_v * scalar_product(ei, eps) * dV;
    if (with_matrix)
      for (unsigned j = 0; j <= i; ++j) Ke(i, j) += two_mu_v * scalar_product(ei, gradN[j]) * dV;
  }
  return two_mu_v * scalar_product(eps, eps) * dV;
}

/// Adds the condensed pressure stiffness B^T (M^-1 K_JJ M^-1) B of the
/// three-field form (B: the cell's dJ couplings, np x dofs) to the lower
/// triangle of Ke, then mirrors the lower triangle into the upper one.
void add_condensed_pressure_stiffness(const CellState& st, const FullMatrix<double>& B, FullMatrix<double>& Ke) {
  const unsigned np = B.m(), dpc = B.n();
  FullMatrix<double> tmp(np, np), G(np, np), GB(np, dpc);
  st.M_inv.mmult(tmp, st.K_JJ);
  tmp.mmult(G, st.M_inv);
  G.mmult(GB, B);
  for (unsigned i = 0; i < dpc; ++i)
    for (unsigned j = 0; j <= i; ++j) {
      double s = 0.0;
      for (unsigned a = 0; a < np; ++a) s += B(a, i) * GB(a, j);
      Ke(i, j) += s;
    }
  for (unsigned i = 0; i < dpc; ++i)
    for (unsigned j = i + 1; j < dpc; ++j) Ke(i, j) = Ke(j, i);
}

}  // namespace

void AxisymmetricSolver::set_viscoelasticity(const std::vector<std::vector<PronyTerm>>& prony_per_layer) {
  if (prony_per_layer.size() != materials_.size())
    throw std::invalid_argument("AxisymmetricSolver: one Prony series (possibly empty) per layer");
  viscoelastic_.assign(materials_.size(), std::nullopt);
  for (std::size_t l = 0; l < materials_.size(); ++l)
    if (!prony_per_layer[l].empty()) viscoelastic_[l] = make_viscoelastic_layer(materials_[l], prony_per_layer[l]);
}

const ViscoelasticMaterial<LayerMaterial>* AxisymmetricSolver::viscoelastic_of(
    const DoFHandler<2>::active_cell_iterator& cell) const {
  if (viscoelastic_.empty() || core_cell_[cell->active_cell_index()]) return nullptr;
  const auto& law = viscoelastic_[cell->material_id()];
  return law ? &*law : nullptr;
}

void AxisymmetricSolver::commit_viscous_history() {
  const unsigned nq = unit_points_.size();
  DisplacementGradients gradients(nq, shape_component_);
  std::vector<Tensor<2, 3>> H(nq);
  for (std::size_t k = 0; k < cells_.size(); ++k) {
    const auto& cell = cells_[k];
    const ViscoelasticMaterial<LayerMaterial>* law = viscoelastic_of(cell);
    if (!law) continue;
    gradients.compute(geometry_[k], solution_, H);
    std::vector<ViscoelasticHistory>& history = viscous_history_[cell->active_cell_index()];
    for (unsigned q = 0; q < nq; ++q) {
      const Tensor<2, 3> F = Tensor<2, 3>(unit_symmetric_tensor<3>()) + H[q];
      law->commit(right_cauchy_green(F), dt_s_, history[q]);
    }
  }
}

const LayerMaterial& AxisymmetricSolver::material_of(const DoFHandler<2>::active_cell_iterator& cell) const {
  return core_cell_[cell->active_cell_index()] ? core_materials_[cell->material_id()] : materials_[cell->material_id()];
}

void AxisymmetricSolver::set_cutting_needle(const RigidNeedle& needle) {
  needle.check();
  cutting_ = true;
  needle_ = needle;
}

void AxisymmetricSolver::set_flat_punch(double radius_m, double z_face_m) {
  if (!(radius_m > 0.0) || !std::isfinite(z_face_m))
    throw std::invalid_argument("AxisymmetricSolver: flat punch needs a positive radius and a finite face height");
  cutting_ = false;
  punch_radius_m_ = radius_m;
  punch_z_m_ = z_face_m;
}

void AxisymmetricSolver::break_layer(int layer) {
  if (layer < 0 || layer >= static_cast<int>(materials_.size())) throw std::out_of_range("break_layer: no such layer");
  broken_layers_[layer] = 1;
  for (std::size_t i = 0; i < cohesive_points_.size(); ++i)
    if (cohesive_points_[i].layer == layer) cohesive_committed_[i].damage = 1.0;
  cohesive_trial_ = cohesive_committed_;
}

bool AxisymmetricSolver::tied_slave(std::size_t node) const {
  const ContactNode& nd = contact_nodes_[node];
  if (nd.partner < 0 || nd.core_side) return false;
  for (const CohesivePoint& cp : cohesive_points_)
    if (cp.outer_z == nd.dof_z)
      return cracks_[cp.layer].kind == LayerCrack::Kind::TiedUntilBroken && !broken_layers_[cp.layer];
  return false;
}

void AxisymmetricSolver::make_constraints(const Vector<double>& u, AffineConstraints<double>& c) const {
  // Newton-increment constraints: Dirichlet (homogeneous), ties of unbroken
  // tied layers, and the flat punch (du = target - u).
  c.clear();
  for (const CohesivePoint& cp : cohesive_points_)
    if (!cp.to_plane && cracks_[cp.layer].kind == LayerCrack::Kind::TiedUntilBroken && !broken_layers_[cp.layer]) {
      c.add_line(cp.outer_r);
      c.add_entry(cp.outer_r, cp.core_r, 1.0);
      c.set_inhomogeneity(cp.outer_r, u[cp.core_r] - u[cp.outer_r]);
      c.add_line(cp.outer_z);
      c.add_entry(cp.outer_z, cp.core_z, 1.0);
      c.set_inhomogeneity(cp.outer_z, u[cp.core_z] - u[cp.outer_z]);
    }
  if (!cutting_)
    for (std::size_t i = 0; i < contact_nodes_.size(); ++i) {
      if (!punch_contact_[i]) continue;
      const ContactNode& nd = contact_nodes_[i];
      if (c.is_constrained(nd.dof_z) || dirichlet_.is_constrained(nd.dof_z)) continue;
      c.add_line(nd.dof_z);
      c.set_inhomogeneity(nd.dof_z, (punch_z_m_ - nd.Z) - u[nd.dof_z]);
      if (settings_.blunt_tip_no_slip && !dirichlet_.is_constrained(nd.dof_r) && !c.is_constrained(nd.dof_r)) {
        c.add_line(nd.dof_r);
        c.set_inhomogeneity(nd.dof_r, punch_lateral_hold_[i] - u[nd.dof_r]);
      }
    }
  c.merge(dirichlet_, AffineConstraints<double>::MergeConflictBehavior::left_object_wins);
  c.close();
}

bool AxisymmetricSolver::assemble_cells(std::size_t begin, std::size_t end, const Vector<double>& u, bool with_matrix) {
  const unsigned degree = settings_.degree;
  const unsigned dpc = fe_.n_dofs_per_cell(), nq = unit_points_.size(), np = n_pressure_modes(degree);
  FullMatrix<double> B(np, dpc);
  std::vector<Tensor<2, 3>> H(nq), H0(nq), gradN(dpc);
  std::vector<SymTensor2> dE(dpc), CC_dE(dpc);
  const std::vector<unsigned>& comp = shape_component_;
  DisplacementGradients gradients(nq, comp);
  CellState st;
  // Viscous stabilisation (Kelvin-Voigt on the step's strain increment):
  // sigma_v = (tau / dt) 2 mu_0 sym(H - H_step_start), mu_0 the layer's
  // initial shear modulus.
  const bool stabilize = settings_.stabilization_time_s > 0.0 && dt_s_ > 0.0 && step_start_.size() == u.size();
  const double stab_ratio = stabilize ? settings_.stabilization_time_s / dt_s_ : 0.0;
  // Pseudo-transient continuation (continue_step): ratio 2 mu_0 sym(H - H_k)
  // on the change from the last pseudo-step's state (not physical energy).
  const bool continuing = continuation_ratio_ > 0.0 && continuation_reference_.size() == u.size();
  std::vector<Tensor<2, 3>> Hk(continuing ? nq : 0);

  for (std::size_t k = begin; k < end; ++k) {
    const auto& cell = cells_[k];
    CellContribution& out = cell_work_[k];
    FullMatrix<double>& Ke = out.Ke;
    Vector<double>& Re = out.Re;
    out.stabilization_J = 0.0;
    const AxisymmetricCellGeometry& g = geometry_[k];
    gradients.compute(g, u, H);
    const ViscousCell viscous{viscoelastic_of(cell), &viscous_history_[cell->active_cell_index()], dt_s_};
    if (!evaluate_cell(material_of(cell), degree, g, H, st, with_matrix, viscous)) return false;
    Ke = 0.0;
    Re = 0.0;
    B = 0.0;
    double two_mu_v = 0.0, two_mu_c = 0.0;
    const LayerMaterial& m = material_of(cell);
    if (stabilize) {
      gradients.compute(g, step_start_, H0);
      two_mu_v = stab_ratio * m.youngs_modulus_Pa() / (1.0 + m.poisson_ratio());
    }
    if (continuing) {
      gradients.compute(g, continuation_reference_, Hk);
      two_mu_c = continuation_ratio_ * m.youngs_modulus_Pa() / (1.0 + m.poisson_ratio());
    }
    for (unsigned q = 0; q < nq; ++q) {
      const double R = g.R_m[q];
      for (unsigned i = 0; i < dpc; ++i) {
        gradN[i] = axisymmetric_shape_gradient(comp[i], g.value(i, q), g.grad(i, q), R);
        dE[i] = strain_variation(st.F[q], gradN[i]);
        Re(i) += scalar_product(st.S[q], dE[i]) * st.dV[q];
      }
      if (stabilize)
        out.stabilization_J += add_stabilization(two_mu_v, H[q] - H0[q], gradN, st.dV[q], with_matrix, Ke, Re);
      if (continuing) add_stabilization(two_mu_c, H[q] - Hk[q], gradN, st.dV[q], with_matrix, Ke, Re);
      if (!with_matrix) continue;
      const Tensor<2, 3> S_full(st.S[q]);
      const Tensor<2, 3> F_inv_T = transpose(invert(st.F[q]));
      for (unsigned i = 0; i < dpc; ++i) {
        CC_dE[i] = st.CC[q] * dE[i];
        const Tensor<2, 3> gNi_S = gradN[i] * S_full;
        for (unsigned j = 0; j <= i; ++j)
          Ke(i, j) += (scalar_product(CC_dE[i], dE[j]) + scalar_product(gNi_S, gradN[j])) * st.dV[q];
        const double dJ_i = st.J[q] * scalar_product(gradN[i], F_inv_T);
        for (unsigned a = 0; a < np; ++a) B(a, i) += st.Np[q][a] * dJ_i * st.dV[q];
      }
    }
    if (with_matrix) add_condensed_pressure_stiffness(st, B, Ke);
  }
  return true;
}

bool AxisymmetricSolver::assemble(const Vector<double>& u, bool with_matrix) {
  TimerOutput::Scope section(timer_, "assemble");
  if (!compute_cell_contributions(u, with_matrix)) return false;
  add_cell_contributions(with_matrix);
  if (!add_cohesive_forces(u, with_matrix)) return false;
  // Needle: penalty contact with friction (cutting tip) or flat punch reactions.
  force_trial_ = NeedleForce{};
  if (cutting_)
    add_needle_contact(u, with_matrix);
  else
    add_punch_reactions();
  force_trial_.total_N = force_trial_.normal_N + force_trial_.friction_N;
  for (std::size_t i = 0; i < residual_.size(); ++i)
    if (!std::isfinite(residual_(i))) return false;
  return true;
}

bool AxisymmetricSolver::compute_cell_contributions(const Vector<double>& u, bool with_matrix) {
  // Cells: computed in parallel (each thread its own range and scratch), added
  // to the global system in cell order, so the result does not depend on the
  // number of threads.
  const std::size_t n_cells = cells_.size();
  const std::size_t n_threads = std::max<std::size_t>(1, std::min<std::size_t>(settings_.assembly_threads, n_cells));
  std::vector<char> ok(n_threads, 1);
  std::vector<std::exception_ptr> errors(n_threads);
  auto run_range = [&](std::size_t t) {
    try {
      ok[t] = assemble_cells(t * n_cells / n_threads, (t + 1) * n_cells / n_threads, u, with_matrix) ? 1 : 0;
    } catch (...) {
      errors[t] = std::current_exception();
    }
  };
  {
    std::vector<std::thread> pool;
    for (std::size_t t = 1; t < n_threads; ++t) pool.emplace_back(run_range, t);
    run_range(0);
    for (auto& th : pool) th.join();
  }
  for (const auto& e : errors)
    if (e) std::rethrow_exception(e);
  for (const char o : ok)
    if (!o) return false;
  return true;
}

void AxisymmetricSolver::add_cell_contributions(bool with_matrix) {
  stabilization_trial_J_ = stabilization_J_;
  if (with_matrix) {
    tangent_ = 0.0;
    bulk_diagonal_ = 0.0;
  }
  residual_ = 0.0;
  for (std::size_t k = 0; k < cells_.size(); ++k) {
    const CellContribution& c = cell_work_[k];
    const std::vector<types::global_dof_index>& dofs = geometry_[k].dofs;
    stabilization_trial_J_ += c.stabilization_J;
    for (unsigned i = 0; i < dofs.size(); ++i) {
      residual_(dofs[i]) += c.Re(i);
      if (with_matrix) bulk_diagonal_(dofs[i]) += c.Ke(i, i);
    }
    if (with_matrix) tangent_.add(dofs, c.Ke, false);
  }
}

bool AxisymmetricSolver::add_cohesive_forces(const Vector<double>& u, bool with_matrix) {
  // Cohesive points: R_outer += A t, R_core -= A t.
  dissipated_trial_J_ = dissipated_J_;
  for (std::size_t k = 0; k < cohesive_points_.size(); ++k) {
    const CohesivePoint& cp = cohesive_points_[k];
    const LayerCrack& crack = cracks_[cp.layer];
    if (crack.kind == LayerCrack::Kind::TiedUntilBroken) {
      // Tied by constraints until broken; afterwards only the faces'
      // no-interpenetration penalty of a fully damaged law remains.
      if (!broken_layers_[cp.layer]) continue;
    }
    CohesiveLawParameters law = crack.law;
    double area_scale = crack.area_scale, kn = crack.opening_scale;
    if (crack.kind == LayerCrack::Kind::TiedUntilBroken) {
      // A broken tied layer keeps a stiff closure penalty only (D = 1).
      law.strength_Pa = 1e3 * materials_[cp.layer].youngs_modulus_Pa();
      law.toughness_J_per_m2 = 1e-3 * law.strength_Pa;
      area_scale = kn = 1.0;
    }
    // Law in the slit's separation (kn x radial opening, sliding); forces on
    // the ring nodes A area_scale (kn t_n, t_t) (see LayerCrack).
    // A wall tied to the crack plane opens by its radial displacement and
    // does not slide on it (the plane is one of symmetry of the cut).
    const double dn = cp.to_plane ? u[cp.outer_r] : u[cp.outer_r] - u[cp.core_r];
    const double dt = cp.to_plane ? 0.0 : u[cp.outer_z] - u[cp.core_z];
    const CohesiveResponse r = cohesive_response(law, cohesive_committed_[k], kn * dn, dt, dt_s_);
    if (!std::isfinite(r.traction[0]) || !std::isfinite(r.traction[1])) return false;
    cohesive_trial_[k] = r.history;
    cohesive_branch_[k] = static_cast<unsigned char>((r.history.max_separation_m > cohesive_committed_[k].max_separation_m ? 1 : 0) |
                                                     (dn > 0.0 ? 2 : 0));
    const double A = cp.area_m2 * area_scale;
    dissipated_trial_J_ += A * (r.history.dissipated_J_per_m2 - cohesive_committed_[k].dissipated_J_per_m2);
    if (cp.to_plane) {
      residual_(cp.outer_r) += A * kn * r.traction[0];
      if (with_matrix) tangent_.add(cp.outer_r, cp.outer_r, A * kn * kn * r.tangent[0][0]);
      continue;
    }
    const double scale[2] = {kn, 1.0};
    const unsigned d[4] = {cp.core_r, cp.core_z, cp.outer_r, cp.outer_z};
    const double sgn[4] = {-1.0, -1.0, 1.0, 1.0};
    for (unsigned i = 0; i < 4; ++i) residual_(d[i]) += sgn[i] * A * scale[i % 2] * r.traction[i % 2];
    if (with_matrix)
      for (unsigned i = 0; i < 4; ++i)
        for (unsigned j = 0; j < 4; ++j)
          tangent_.add(d[i], d[j], sgn[i] * sgn[j] * A * scale[i % 2] * scale[j % 2] * r.tangent[i % 2][j % 2]);
  }
  return true;
}

void AxisymmetricSolver::add_needle_contact(const Vector<double>& u, bool with_matrix) {
  // Cutting tip: penalty contact with Coulomb friction at every contact node.
  const Vec2 edge{needle_.edge_radius_m, needle_.z_tip_m};
  for (std::size_t i = 0; i < contact_nodes_.size(); ++i) {
    const ContactNode& nd = contact_nodes_[i];
    const Vec2 x{nd.R + u[nd.dof_r], nd.Z + u[nd.dof_z]};
    const ContactPenalty penalty{penalty_[i], settings_.contact_rounding * mesh_.tip_element_size_m};
    NodalContactResponse resp;
    ContactPoint c;
    if (nd.core_side) {
      resp = core_wall_contact(needle_, x, penalty,
                               settings_.hold_crack_line ? -1.0 : settings_.edge_rounding * mesh_.tip_element_size_m);
      c.penetration_m = std::max(x[0] - needle_.edge_radius_m, 0.0);
    } else {
      c = outer_contact(needle_, x, settings_.edge_rounding * mesh_.tip_element_size_m);
      resp = nodal_contact(c, x, edge, friction_committed_[i], friction_[nd.layer], penalty,
                           settings_.friction_penalty * penalty_[i],
                           settings_.friction_min_slip * mesh_.tip_element_size_m);
    }
    friction_trial_[i] = resp.history;
    contact_branch_[i] = resp.history.in_contact ? 1 : 0;
    if (!resp.history.in_contact) continue;
    if (debug_contacts_)
      std::cout << "        node R " << nd.R * 1e3 << " Z " << nd.Z * 1e3 << (nd.core_side ? " core" : " outer")
                << " x (" << x[0] * 1e3 << ", " << x[1] * 1e3 << ") pen " << c.penetration_m * 1e6 << " um n ("
                << c.normal[0] << "," << c.normal[1] << ") k " << penalty_[i] << " f " << resp.normal_force[0] << ","
                << resp.normal_force[1] << " ft " << resp.friction_force[1] << std::endl;
    const unsigned d[2] = {nd.dof_r, nd.dof_z};
    for (unsigned a = 0; a < 2; ++a) {
      residual_(d[a]) -= resp.normal_force[a] + resp.friction_force[a];
      if (with_matrix)
        for (unsigned b = 0; b < 2; ++b) tangent_.add(d[a], d[b], -resp.dforce_dx[a][b]);
    }
    force_trial_.normal_N -= resp.normal_force[1];
    force_trial_.friction_N -= resp.friction_force[1];
    ++force_trial_.nodes_in_contact;
  }
}

void AxisymmetricSolver::add_punch_reactions() {
  for (std::size_t i = 0; i < contact_nodes_.size(); ++i)
    if (punch_contact_[i]) {
      force_trial_.normal_N -= residual_(contact_nodes_[i].dof_z);  // R_z < 0 where the punch presses
      ++force_trial_.nodes_in_contact;
    }
}

double AxisymmetricSolver::free_residual_norm(const AffineConstraints<double>& c) const {
  // Residual of the unknowns left free by the constraints: a constrained dof
  // hands its residual to its masters (a tied crack node to its partner).
  Vector<double> r(residual_);
  for (std::size_t i = 0; i < r.size(); ++i) {
    if (!c.is_constrained(i)) continue;
    if (const auto* entries = c.get_constraint_entries(i))
      for (const auto& [j, w] : *entries) r(j) += w * residual_(i);
  }
  double s = 0.0;
  for (std::size_t i = 0; i < r.size(); ++i)
    if (!c.is_constrained(i)) s += r(i) * r(i);
  return std::sqrt(s);
}

void AxisymmetricSolver::update_penalties() {
  // k_n = contact_penalty x the bulk stiffness at the node (mean of its two
  // diagonal entries; the bulk tangent of the last converged state).
  for (std::size_t i = 0; i < contact_nodes_.size(); ++i) {
    const ContactNode& nd = contact_nodes_[i];
    const double k = 0.5 * (bulk_diagonal_(nd.dof_r) + bulk_diagonal_(nd.dof_z));
    penalty_[i] = settings_.contact_penalty * std::max(k, 1e-12);
  }
}

void AxisymmetricSolver::commit() {
  commit_viscous_history();
  cohesive_committed_ = cohesive_trial_;
  friction_committed_ = friction_trial_;
  dissipated_J_ = dissipated_trial_J_;
  stabilization_J_ = stabilization_trial_J_;
  force_ = force_trial_;
}

AxisymmetricSolver::Snapshot AxisymmetricSolver::snapshot() const {
  return {solution_,          last_increment_,     cohesive_committed_, friction_committed_,
          punch_contact_,     punch_lateral_hold_, broken_layers_,      dissipated_J_,
          stabilization_J_,   viscous_history_};
}

void AxisymmetricSolver::restore(const Snapshot& s) {
  solution_ = s.solution;
  last_increment_ = s.last_increment;
  cohesive_committed_ = cohesive_trial_ = s.cohesive;
  friction_committed_ = friction_trial_ = s.friction;
  punch_contact_ = s.punch_contact;
  punch_lateral_hold_ = s.punch_lateral_hold;
  broken_layers_ = s.broken_layers;
  dissipated_J_ = dissipated_trial_J_ = s.dissipated_J;
  stabilization_J_ = stabilization_trial_J_ = s.stabilization_J;
  viscous_history_ = s.viscous_history;
  step_start_ = solution_;
  const double dt_s = dt_s_;  // the restored state itself: no step, no viscous advance
  dt_s_ = 0.0;
  assemble(solution_, true);
  dt_s_ = dt_s;
  force_ = force_trial_;
  update_penalties();
}

}  // namespace puncture::fem
