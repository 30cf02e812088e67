// finite_strain_assembly.cc: the FiniteStrainSolver's cell states, residual and tangent
// (three-field condensation) and the cell fields for output (finite_strain_solver.hpp).
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
