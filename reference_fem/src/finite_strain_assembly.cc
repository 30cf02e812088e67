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

/// A viscoelastic cell's law, its points' committed history and the time step.
struct ViscousCell {
  const ViscoelasticMaterial<LayerMaterial>* law = nullptr;  ///< nullptr: elastic
  const std::vector<ViscoelasticHistory>* history = nullptr;  ///< per quadrature point
  double dt_s = 0.0;
};

/// Evaluates the constitutive state of a not-removed cell from the
/// displacement gradients (the isochoric part viscoelastic if `viscous` has a
/// law). Returns false if any point is inverted or non-finite (the caller
/// then rejects the state).
bool evaluate_cell(const LayerMaterial& material, const ViscousCell& viscous, VolumetricFormulation formulation,
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
    if (viscous.law != nullptr)
      viscous.law->isochoric_stress_and_tangent(C, viscous.dt_s, (*viscous.history)[q], st.S[q], st.CC[q]);
    else
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

/// What the assembly of one cell works in: its values, its element matrix and
/// vector, and the scratch of the three-field condensation (sized once).
struct CellScratch {
  CellScratch(const FiniteElement<3>& fe, unsigned degree)
      : fev(fe, QGauss<3>(degree + 1), update_values | update_gradients | update_JxW_values),
        fefv(fe, QGauss<2>(degree + 1), update_values | update_JxW_values),
        dpc(fe.n_dofs_per_cell()),
        nq(fev.n_quadrature_points),
        np(n_pressure_modes(degree)),
        Ke(dpc, dpc),
        Re(dpc),
        minus_Re(dpc),
        dofs(dpc),
        grad_u(nq),
        grad_N(dpc),
        dE(dpc),
        CC_dE(dpc),
        B(np, dpc),
        G(np, np),
        tmp(np, np),
        GB(np, dpc) {}
  FEValues<3> fev;
  FEFaceValues<3> fefv;
  const FEValuesExtractors::Vector displacement{0};
  unsigned dpc, nq, np;
  FullMatrix<double> Ke;  ///< element tangent (lower triangle filled, then mirrored)
  Vector<double> Re, minus_Re;  ///< element residual f_int - f_ext and its negative
  std::vector<types::global_dof_index> dofs;
  std::vector<Tensor<2, 3>> grad_u, grad_N;
  std::vector<SymTensor2> dE, CC_dE;
  FullMatrix<double> B, G, tmp, GB;  ///< three-field condensation
  CellState st;
};

/// Removed cell: small-strain linear void material of `fraction` x E.
void add_void_cell(const LayerMaterial& material, double fraction, bool with_matrix, CellScratch& s) {
  double lambda = 0.0, mu = 0.0;
  void_lame(material, fraction, lambda, mu);
  const SymTensor2 I = unit_symmetric_tensor<3>();
  for (unsigned q = 0; q < s.nq; ++q) {
    const SymTensor2 eps = symmetrize(s.grad_u[q]);
    const SymTensor2 sigma = lambda * trace(eps) * I + 2.0 * mu * eps;
    const double dV = s.fev.JxW(q);
    for (unsigned i = 0; i < s.dpc; ++i) {
      s.dE[i] = s.fev[s.displacement].symmetric_gradient(i, q);
      s.Re(i) += scalar_product(sigma, s.dE[i]) * dV;
    }
    if (with_matrix)
      for (unsigned i = 0; i < s.dpc; ++i) {
        const SymTensor2 sig_i = lambda * trace(s.dE[i]) * I + 2.0 * mu * s.dE[i];
        for (unsigned j = 0; j <= i; ++j) s.Ke(i, j) += scalar_product(sig_i, s.dE[j]) * dV;
      }
  }
}

/// Three-field condensation of the volumetric tangent: K += B^T (M^-1 K_JJ M^-1) B.
void add_condensed_volumetric_tangent(CellScratch& s) {
  s.st.M_inv.mmult(s.tmp, s.st.K_JJ);
  s.tmp.mmult(s.G, s.st.M_inv);
  s.G.mmult(s.GB, s.B);
  for (unsigned i = 0; i < s.dpc; ++i)
    for (unsigned j = 0; j <= i; ++j) {
      double sum = 0.0;
      for (unsigned a = 0; a < s.np; ++a) sum += s.B(a, i) * s.GB(a, j);
      s.Ke(i, j) += sum;
    }
}

/// Hyperelastic cell: residual int S : dE dV and (with_matrix) the material
/// and geometric tangent, condensed for the three-field formulation. Returns
/// false if a quadrature point is inverted or non-finite.
bool add_solid_cell(const LayerMaterial& material, const ViscousCell& viscous, VolumetricFormulation formulation,
                    unsigned degree, bool with_matrix, CellScratch& s) {
  if (!evaluate_cell(material, viscous, formulation, degree, s.fev, s.grad_u, s.st)) return false;
  const bool three_field = formulation == VolumetricFormulation::three_field;
  if (three_field) s.B = 0.0;
  for (unsigned q = 0; q < s.nq; ++q) {
    const double dV = s.fev.JxW(q);
    const Tensor<2, 3> S_full(s.st.S[q]);
    const Tensor<2, 3> F_inv_T = transpose(invert(s.st.F[q]));
    for (unsigned i = 0; i < s.dpc; ++i) {
      s.grad_N[i] = s.fev[s.displacement].gradient(i, q);
      s.dE[i] = strain_variation(s.st.F[q], s.grad_N[i]);
      s.Re(i) += scalar_product(s.st.S[q], s.dE[i]) * dV;
    }
    if (!with_matrix) continue;
    for (unsigned i = 0; i < s.dpc; ++i) {
      s.CC_dE[i] = s.st.CC[q] * s.dE[i];
      const Tensor<2, 3> gNi_S = s.grad_N[i] * S_full;
      for (unsigned j = 0; j <= i; ++j)
        s.Ke(i, j) += (scalar_product(s.CC_dE[i], s.dE[j]) + scalar_product(gNi_S, s.grad_N[j])) * dV;
    }
    if (three_field)
      for (unsigned i = 0; i < s.dpc; ++i) {
        const double dJ_i = s.st.J[q] * scalar_product(s.grad_N[i], F_inv_T);
        for (unsigned a = 0; a < s.np; ++a) s.B(a, i) += s.st.Np[q][a] * dJ_i * dV;
      }
  }
  if (with_matrix && three_field) add_condensed_volumetric_tangent(s);
  return true;
}

/// Dead-load tractions (per reference area) on the cell's boundary faces
/// enter the residual as -f_ext.
void add_face_tractions(const FiniteStrainSolver::CellIterator& cell,
                        const std::map<types::boundary_id, Tensor<1, 3>>& tractions, const FiniteElement<3>& fe,
                        CellScratch& s) {
  if (tractions.empty()) return;
  for (unsigned f = 0; f < cell->n_faces(); ++f) {
    if (!cell->face(f)->at_boundary()) continue;
    const auto it = tractions.find(cell->face(f)->boundary_id());
    if (it == tractions.end()) continue;
    s.fefv.reinit(cell, f);
    for (unsigned q = 0; q < s.fefv.n_quadrature_points; ++q)
      for (unsigned i = 0; i < s.dpc; ++i) {
        const unsigned comp = fe.system_to_component_index(i).first;
        s.Re(i) -= it->second[comp] * s.fefv.shape_value(i, q) * s.fefv.JxW(q);
      }
  }
}

/// Mirrors the cell tangent's lower triangle and adds the cell into the
/// global residual and, with constraints, into the Newton system (tangent,
/// rhs = -R with the increment constraints applied).
void scatter_cell(const FiniteStrainSolver::CellIterator& cell, const AffineConstraints<double>* constraints,
                  CellScratch& s, TrilinosWrappers::SparseMatrix& tangent, TrilinosWrappers::MPI::Vector& rhs,
                  TrilinosWrappers::MPI::Vector& residual) {
  for (unsigned i = 0; i < s.dpc; ++i)
    for (unsigned j = i + 1; j < s.dpc; ++j) s.Ke(i, j) = s.Ke(j, i);
  cell->get_dof_indices(s.dofs);
  residual.add(s.dofs, s.Re);
  if (constraints == nullptr) return;
  for (unsigned i = 0; i < s.dpc; ++i) s.minus_Re(i) = -s.Re(i);
  constraints->distribute_local_to_global(s.Ke, s.minus_Re, s.dofs, tangent, rhs);
}

}  // namespace

FiniteStrainSolver::AssemblyResult FiniteStrainSolver::assemble(
    const TrilinosWrappers::MPI::Vector& u, bool with_matrix,
    const AffineConstraints<double>* constraints) {
  TimerOutput::Scope section(timer_, "assemble");
  CellScratch s(fe_, settings_.degree);
  if (with_matrix) tangent_ = 0.0;
  rhs_ = 0.0;
  residual_ = 0.0;
  bool valid = true;
  for (const auto& cell : dof_handler_.active_cell_iterators()) {
    if (!cell->is_locally_owned() || !valid) continue;
    s.fev.reinit(cell);
    s.fev[s.displacement].get_function_gradients(u, s.grad_u);
    s.Ke = 0.0;
    s.Re = 0.0;
    const LayerMaterial& material = materials_[cell->material_id()];
    if (removed_[cell->active_cell_index()]) {
      add_void_cell(material, settings_.void_stiffness_fraction, with_matrix, s);
    } else if (!add_solid_cell(material, {viscoelastic_of(cell), viscous_history_of(cell), time_step_s_},
                               settings_.formulation, settings_.degree, with_matrix, s)) {
      valid = false;
      continue;
    }
    add_face_tractions(cell, tractions_, fe_, s);
    scatter_cell(cell, with_matrix ? constraints : nullptr, s, tangent_, rhs_, residual_);
  }
  add_anchor_springs(u, with_matrix ? constraints : nullptr);
  if (with_matrix) tangent_.compress(VectorOperation::add);
  rhs_.compress(VectorOperation::add);
  residual_.compress(VectorOperation::add);
  add_released_load(constraints);
  const bool all_valid = Utilities::MPI::min(valid ? 1 : 0, mpi_communicator()) == 1;
  return {all_valid && std::isfinite(residual_.l2_norm())};
}

void FiniteStrainSolver::add_anchor_springs(const TrilinosWrappers::MPI::Vector& u,
                                            const AffineConstraints<double>* constraints) {
  // f = k (u - anchor) on free, locally owned dofs.
  for (const auto& [dof, spring] : anchors_) {
    const double k = anchor_scale_ * spring.stiffness_N_per_m;
    if (targets_.count(dof) || k == 0.0) continue;
    const double f = k * (u[dof] - spring.anchor_m);
    residual_[dof] += f;
    if (constraints != nullptr) {
      rhs_[dof] -= f;
      tangent_.add(dof, dof, k);
    }
  }
}

void FiniteStrainSolver::add_released_load(const AffineConstraints<double>* constraints) {
  // The frozen removal load (internal force of removed cells) is a dead load.
  if (released_fraction_ <= 0.0) return;
  residual_.add(released_fraction_, released_force_);
  if (constraints == nullptr) return;
  TrilinosWrappers::MPI::Vector free_part(released_force_);
  for (const auto& [dof, target] : targets_)
    if (locally_owned_.is_element(dof)) free_part[dof] = 0.0;
  free_part.compress(VectorOperation::insert);
  rhs_.add(-released_fraction_, free_part);
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
        !removed_[c] && evaluate_cell(materials_[cell->material_id()],
                                      {viscoelastic_of(cell), viscous_history_of(cell), time_step_s_},
                                      settings_.formulation, settings_.degree, fev, grad_u, st);
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
