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

namespace {

/// Basis of the discontinuous pressure / dilatation space P_{k-1} on the unit
/// cell: {1} for Q1 (mean dilatation), {1, xi-1/2, eta-1/2, zeta-1/2} for Q2.
unsigned int n_pressure_modes(unsigned int degree) { return degree == 1 ? 1 : 4; }

double pressure_mode(unsigned int a, const Point<3>& unit_point) {
  return a == 0 ? 1.0 : unit_point[a - 1] - 0.5;
}

/// Constitutive state of one (not removed) cell at its quadrature points.
struct CellState {
  std::vector<Tensor<2, 3>> F;
  std::vector<double> J;
  std::vector<SymTensor2> C_inv;
  std::vector<SymTensor2> S;   ///< total second Piola-Kirchhoff stress, Pa
  std::vector<SymTensor4> CC;  ///< tangent at fixed projected pressure, Pa
  // Three-field condensation data (n_p = number of pressure modes):
  FullMatrix<double> M_inv;           ///< (int N_a N_b dV)^{-1}
  FullMatrix<double> K_JJ;            ///< int Psi''(Jtilde) N_a N_b dV
  std::vector<std::vector<double>> Np;  ///< [q][a]
  void resize(unsigned nq, unsigned np) {
    F.resize(nq);
    J.resize(nq);
    C_inv.resize(nq);
    S.resize(nq);
    CC.resize(nq);
    M_inv.reinit(np, np);
    K_JJ.reinit(np, np);
    Np.assign(nq, std::vector<double>(np, 0.0));
  }
};

/// Evaluates the constitutive state of a not-removed cell from the
/// displacement gradients. Returns false if any point is inverted or
/// non-finite (the caller then rejects the state).
bool evaluate_cell(const LayerMaterial& material, VolumetricFormulation formulation,
                   unsigned int degree, const FEValues<3>& fev,
                   const std::vector<Tensor<2, 3>>& grad_u, CellState& st) {
  const unsigned nq = fev.n_quadrature_points;
  const unsigned np = n_pressure_modes(degree);
  st.resize(nq, np);
  const Tensor<2, 3> I = unit_symmetric_tensor<3>();
  for (unsigned q = 0; q < nq; ++q) {
    st.F[q] = I + grad_u[q];
    st.J[q] = determinant(st.F[q]);
    if (!(st.J[q] > 0.0) || !std::isfinite(st.J[q])) return false;
  }
  std::vector<double> pressure(nq, 0.0);
  std::vector<double> J_tilde(nq, 0.0);
  const VolumetricLaw& vol = material.volumetric();
  if (formulation == VolumetricFormulation::three_field) {
    FullMatrix<double> M(np, np);
    std::vector<double> bJ(np, 0.0), bp(np, 0.0), cJ(np, 0.0), cp(np, 0.0);
    const auto& unit_points = fev.get_quadrature().get_points();
    for (unsigned q = 0; q < nq; ++q) {
      for (unsigned a = 0; a < np; ++a) st.Np[q][a] = pressure_mode(a, unit_points[q]);
      const double dV = fev.JxW(q);
      for (unsigned a = 0; a < np; ++a) {
        bJ[a] += st.Np[q][a] * st.J[q] * dV;
        for (unsigned b = 0; b < np; ++b) M(a, b) += st.Np[q][a] * st.Np[q][b] * dV;
      }
    }
    st.M_inv.invert(M);
    for (unsigned a = 0; a < np; ++a)
      for (unsigned b = 0; b < np; ++b) cJ[a] += st.M_inv(a, b) * bJ[b];
    st.K_JJ = 0.0;
    for (unsigned q = 0; q < nq; ++q) {
      for (unsigned a = 0; a < np; ++a) J_tilde[q] += cJ[a] * st.Np[q][a];
      if (!(J_tilde[q] > 0.0) || !std::isfinite(J_tilde[q])) return false;
      const double dV = fev.JxW(q);
      const double dp = vol.dpressure_dJ(J_tilde[q]);
      for (unsigned a = 0; a < np; ++a) {
        bp[a] += st.Np[q][a] * vol.pressure(J_tilde[q]) * dV;
        for (unsigned b = 0; b < np; ++b) st.K_JJ(a, b) += dp * st.Np[q][a] * st.Np[q][b] * dV;
      }
    }
    for (unsigned a = 0; a < np; ++a)
      for (unsigned b = 0; b < np; ++b) cp[a] += st.M_inv(a, b) * bp[b];
    for (unsigned q = 0; q < nq; ++q)
      for (unsigned a = 0; a < np; ++a) pressure[q] += cp[a] * st.Np[q][a];
  } else {
    for (unsigned q = 0; q < nq; ++q) pressure[q] = vol.pressure(st.J[q]);
  }
  for (unsigned q = 0; q < nq; ++q) {
    const SymTensor2 C = right_cauchy_green(st.F[q]);
    st.C_inv[q] = invert(C);
    material.isochoric_stress_and_tangent(C, st.S[q], st.CC[q]);
    add_volumetric_at_fixed_pressure(st.C_inv[q], st.J[q], pressure[q], st.S[q], st.CC[q]);
    if (formulation == VolumetricFormulation::one_field)
      st.CC[q] += (st.J[q] * st.J[q] * vol.dpressure_dJ(st.J[q])) *
                  outer_product(st.C_inv[q], st.C_inv[q]);
    if (!all_finite(st.S[q])) return false;
  }
  return true;
}

/// Lame constants of the void material of a removed cell.
void void_lame(const LayerMaterial& m, double fraction, double& lambda, double& mu) {
  const double E = fraction * m.youngs_modulus_Pa();
  const double nu = 0.3;
  lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  mu = E / (2.0 * (1.0 + nu));
}

}  // namespace

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

FiniteStrainSolver::AssemblyResult FiniteStrainSolver::assemble(
    const TrilinosWrappers::MPI::Vector& u, bool with_matrix,
    const AffineConstraints<double>* constraints) {
  const unsigned degree = settings_.degree;
  const QGauss<3> quadrature(degree + 1);
  const QGauss<2> face_quadrature(degree + 1);
  FEValues<3> fev(fe_, quadrature, update_values | update_gradients | update_JxW_values);
  FEFaceValues<3> fefv(fe_, face_quadrature, update_values | update_JxW_values);
  const FEValuesExtractors::Vector displacement(0);
  const unsigned dpc = fe_.n_dofs_per_cell();
  const unsigned nq = quadrature.size();
  const unsigned np = n_pressure_modes(degree);

  FullMatrix<double> Ke(dpc, dpc);
  Vector<double> Re(dpc), minus_Re(dpc);
  std::vector<types::global_dof_index> dofs(dpc);
  std::vector<Tensor<2, 3>> grad_u(nq);
  std::vector<Tensor<2, 3>> grad_N(dpc);
  std::vector<SymTensor2> dE(dpc), CC_dE(dpc);
  FullMatrix<double> B(np, dpc), G(np, np), tmp(np, np), GB(np, dpc);
  CellState st;

  if (with_matrix) tangent_ = 0.0;
  rhs_ = 0.0;
  residual_ = 0.0;
  bool valid = true;

  for (const auto& cell : dof_handler_.active_cell_iterators()) {
    if (!cell->is_locally_owned() || !valid) continue;
    fev.reinit(cell);
    fev[displacement].get_function_gradients(u, grad_u);
    Ke = 0.0;
    Re = 0.0;
    const LayerMaterial& material = materials_[cell->material_id()];

    if (removed_[cell->active_cell_index()]) {
      double lambda = 0.0, mu = 0.0;
      void_lame(material, settings_.void_stiffness_fraction, lambda, mu);
      const SymTensor2 I = unit_symmetric_tensor<3>();
      for (unsigned q = 0; q < nq; ++q) {
        const SymTensor2 eps = symmetrize(grad_u[q]);
        const SymTensor2 sigma = lambda * trace(eps) * I + 2.0 * mu * eps;
        const double dV = fev.JxW(q);
        for (unsigned i = 0; i < dpc; ++i) {
          dE[i] = fev[displacement].symmetric_gradient(i, q);
          Re(i) += scalar_product(sigma, dE[i]) * dV;
        }
        if (with_matrix)
          for (unsigned i = 0; i < dpc; ++i) {
            const SymTensor2 sig_i = lambda * trace(dE[i]) * I + 2.0 * mu * dE[i];
            for (unsigned j = 0; j <= i; ++j) Ke(i, j) += scalar_product(sig_i, dE[j]) * dV;
          }
      }
    } else {
      if (!evaluate_cell(material, settings_.formulation, degree, fev, grad_u, st)) {
        valid = false;
        continue;
      }
      if (settings_.formulation == VolumetricFormulation::three_field) B = 0.0;
      for (unsigned q = 0; q < nq; ++q) {
        const double dV = fev.JxW(q);
        const Tensor<2, 3> S_full(st.S[q]);
        const Tensor<2, 3> F_inv_T = transpose(invert(st.F[q]));
        for (unsigned i = 0; i < dpc; ++i) {
          grad_N[i] = fev[displacement].gradient(i, q);
          dE[i] = strain_variation(st.F[q], grad_N[i]);
          Re(i) += scalar_product(st.S[q], dE[i]) * dV;
        }
        if (!with_matrix) continue;
        for (unsigned i = 0; i < dpc; ++i) {
          CC_dE[i] = st.CC[q] * dE[i];
          const Tensor<2, 3> gNi_S = grad_N[i] * S_full;
          for (unsigned j = 0; j <= i; ++j)
            Ke(i, j) += (scalar_product(CC_dE[i], dE[j]) + scalar_product(gNi_S, grad_N[j])) * dV;
        }
        if (settings_.formulation == VolumetricFormulation::three_field)
          for (unsigned i = 0; i < dpc; ++i) {
            const double dJ_i = st.J[q] * scalar_product(grad_N[i], F_inv_T);
            for (unsigned a = 0; a < np; ++a) B(a, i) += st.Np[q][a] * dJ_i * dV;
          }
      }
      if (with_matrix && settings_.formulation == VolumetricFormulation::three_field) {
        // K += B^T (M^-1 K_JJ M^-1) B
        st.M_inv.mmult(tmp, st.K_JJ);
        tmp.mmult(G, st.M_inv);
        G.mmult(GB, B);
        for (unsigned i = 0; i < dpc; ++i)
          for (unsigned j = 0; j <= i; ++j) {
            double s = 0.0;
            for (unsigned a = 0; a < np; ++a) s += B(a, i) * GB(a, j);
            Ke(i, j) += s;
          }
      }
    }
    // Dead-load tractions (per reference area) enter the residual as -f_ext.
    if (!tractions_.empty())
      for (unsigned f = 0; f < cell->n_faces(); ++f) {
        if (!cell->face(f)->at_boundary()) continue;
        const auto it = tractions_.find(cell->face(f)->boundary_id());
        if (it == tractions_.end()) continue;
        fefv.reinit(cell, f);
        for (unsigned q = 0; q < fefv.n_quadrature_points; ++q)
          for (unsigned i = 0; i < dpc; ++i) {
            const unsigned comp = fe_.system_to_component_index(i).first;
            Re(i) -= it->second[comp] * fefv.shape_value(i, q) * fefv.JxW(q);
          }
      }
    for (unsigned i = 0; i < dpc; ++i)
      for (unsigned j = i + 1; j < dpc; ++j) Ke(i, j) = Ke(j, i);
    cell->get_dof_indices(dofs);
    residual_.add(dofs, Re);
    if (with_matrix && constraints != nullptr) {
      for (unsigned i = 0; i < dpc; ++i) minus_Re(i) = -Re(i);
      constraints->distribute_local_to_global(Ke, minus_Re, dofs, tangent_, rhs_);
    }
  }
  // Anchor springs: f = k (u - anchor) on free, locally owned dofs.
  for (const auto& [dof, spring] : anchors_) {
    const double k = anchor_scale_ * spring.stiffness_N_per_m;
    if (targets_.count(dof) || k == 0.0) continue;
    const double f = k * (u[dof] - spring.anchor_m);
    residual_[dof] += f;
    if (with_matrix && constraints != nullptr) {
      rhs_[dof] -= f;
      tangent_.add(dof, dof, k);
    }
  }
  if (with_matrix) tangent_.compress(VectorOperation::add);
  rhs_.compress(VectorOperation::add);
  residual_.compress(VectorOperation::add);
  // Frozen removal load (internal force of removed cells, a dead load).
  if (released_fraction_ > 0.0) {
    residual_.add(released_fraction_, released_force_);
    if (constraints != nullptr) {
      TrilinosWrappers::MPI::Vector free_part(released_force_);
      for (const auto& [dof, target] : targets_)
        if (locally_owned_.is_element(dof)) free_part[dof] = 0.0;
      free_part.compress(VectorOperation::insert);
      rhs_.add(-released_fraction_, free_part);
    }
  }
  const bool all_valid = Utilities::MPI::min(valid ? 1 : 0, mpi_communicator()) == 1;
  return {all_valid && std::isfinite(residual_.l2_norm())};
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

CellFields FiniteStrainSolver::cell_fields() const {
  const unsigned n = triangulation_.n_active_cells();
  CellFields out;
  out.jacobian.assign(n, 0.0);
  out.von_mises_Pa.assign(n, 0.0);
  out.max_principal_stretch.assign(n, 0.0);
  out.material_id.assign(n, 0.0);
  out.removed.assign(n, 0.0);
  const QGauss<3> quadrature(settings_.degree + 1);
  FEValues<3> fev(fe_, quadrature, update_values | update_gradients | update_JxW_values);
  const FEValuesExtractors::Vector displacement(0);
  std::vector<Tensor<2, 3>> grad_u(quadrature.size());
  CellState st;
  for (const auto& cell : dof_handler_.active_cell_iterators()) {
    if (!cell->is_locally_owned()) continue;
    const unsigned c = cell->active_cell_index();
    fev.reinit(cell);
    fev[displacement].get_function_gradients(solution_ghosted_, grad_u);
    out.material_id[c] = cell->material_id();
    out.removed[c] = removed_[c] ? 1.0 : 0.0;
    double J_sum = 0.0, vm_sum = 0.0, stretch = 0.0;
    const bool have_state =
        !removed_[c] && evaluate_cell(materials_[cell->material_id()], settings_.formulation,
                                      settings_.degree, fev, grad_u, st);
    for (unsigned q = 0; q < grad_u.size(); ++q) {
      const Tensor<2, 3> F = unit_symmetric_tensor<3>() + grad_u[q];
      const double J = determinant(F);
      J_sum += J;
      const auto ev = eigenvalues(right_cauchy_green(F));
      stretch = std::max(stretch, std::sqrt(std::max(ev[0], 0.0)));
      if (have_state) {
        const Tensor<2, 3> sigma = (1.0 / J) * F * Tensor<2, 3>(st.S[q]) * transpose(F);
        const SymTensor2 s = deviator(symmetrize(sigma));
        vm_sum += std::sqrt(1.5 * scalar_product(s, s));
      }
    }
    out.jacobian[c] = J_sum / grad_u.size();
    out.von_mises_Pa[c] = vm_sum / grad_u.size();
    out.max_principal_stretch[c] = stretch;
  }
  return out;
}

}  // namespace puncture::fem
