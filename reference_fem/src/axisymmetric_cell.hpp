// axisymmetric_cell.hpp: the constitutive state of one cell of the
// axisymmetric solver, shared by its assembly (axisymmetric_solver.cc) and
// its output (axisymmetric_solver_output.cc). Internal to reference_fem/src
// (not part of the public headers).
//
// In:  a cell's undeformed geometry (AxisymmetricCellGeometry: values,
//      gradients, quadrature points, JxW; made from its FEValues<2> by
//      cell_geometry) and a nodal displacement vector (u_R, u_Z in m); the
//      layer's LayerMaterial
//      and, for a viscoelastic layer, its law, the points' committed Prony
//      histories and the time step (s).
// Out: per quadrature point F, J, the ring volume dV = 2 pi R JxW (m^3), the
//      second Piola-Kirchhoff stress S (Pa) and its tangent CC, plus the
//      three-field condensation data (Q1-P0 or Q2-P1; see
//      finite_strain_solver.hpp); false for an inverted or non-finite state.
#pragma once

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>

#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <puncture/fem/axisymmetric_solver.hpp>
#include <puncture/fem/hyperelastic_materials.hpp>
#include <puncture/fem/kinematics.hpp>
#include <puncture/fem/viscoelastic_material.hpp>

namespace puncture::fem::axisymmetric_cell {

constexpr double kTwoPi = 6.283185307179586;

/// Modes of the discontinuous pressure / dilatation space on the unit cell:
/// {1} for Q1, {1, xi - 1/2, eta - 1/2} for Q2.
inline unsigned n_pressure_modes(unsigned degree) { return degree == 1 ? 1 : 3; }
inline double pressure_mode(unsigned a, const dealii::Point<2>& p) { return a == 0 ? 1.0 : p[a - 1] - 0.5; }

/// Constitutive state of one cell at its quadrature points (three-field,
/// condensed; see finite_strain_solver.hpp).
struct CellState {
  std::vector<dealii::Tensor<2, 3>> F;
  std::vector<double> J, dV;
  std::vector<SymTensor2> S;
  std::vector<SymTensor4> CC;
  dealii::FullMatrix<double> M_inv, K_JJ;
  std::vector<std::vector<double>> Np;
  dealii::FullMatrix<double> M;  ///< scratch: the pressure modes' mass matrix
};

/// Most quadrature points of a cell (QGauss(3) on Q2: 9).
constexpr unsigned kMaxQuadraturePoints = 9;
/// Most pressure modes of a cell (Q2-P1: 3).
constexpr unsigned kMaxPressureModes = 3;

/// The geometry of the cell fev was last reinitialised on (dofs: its dofs;
/// unit_points: the quadrature's points, which must outlive the result).
inline AxisymmetricCellGeometry cell_geometry(const dealii::FEValues<2>& fev,
                                              const std::vector<dealii::types::global_dof_index>& dofs,
                                              const std::vector<dealii::Point<2>>& unit_points) {
  AxisymmetricCellGeometry g;
  g.n_q = fev.n_quadrature_points;
  g.dofs_per_cell = fev.dofs_per_cell;
  if (g.n_q > kMaxQuadraturePoints)
    throw std::logic_error("axisymmetric cell: more quadrature points than kMaxQuadraturePoints");
  g.dofs = dofs;
  g.unit_points = &unit_points;
  g.R_m.resize(g.n_q);
  g.JxW_m2.resize(g.n_q);
  g.shape_value.resize(g.n_q * g.dofs_per_cell);
  g.shape_grad.resize(g.n_q * g.dofs_per_cell);
  for (unsigned q = 0; q < g.n_q; ++q) {
    g.R_m[q] = fev.quadrature_point(q)[0];
    g.JxW_m2[q] = fev.JxW(q);
    for (unsigned i = 0; i < g.dofs_per_cell; ++i) {
      g.shape_value[q * g.dofs_per_cell + i] = fev.shape_value(i, q);
      g.shape_grad[q * g.dofs_per_cell + i] = fev.shape_grad(i, q);
    }
  }
  return g;
}

/// A viscoelastic cell's law, its points' committed histories and the step
/// (law nullptr: elastic).
struct ViscousCell {
  const ViscoelasticMaterial<LayerMaterial>* law = nullptr;
  const std::vector<ViscoelasticHistory>* history = nullptr;
  double dt_s = 0.0;
};

/// Evaluates st at the cell of geometry g from the displacement gradients H at
/// its points (with_tangent: also CC and K_JJ); false if a point is inverted
/// or its stress non-finite. st keeps its storage from one cell to the next.
inline bool evaluate_cell(const LayerMaterial& material, unsigned degree, const AxisymmetricCellGeometry& g,
                          const std::vector<dealii::Tensor<2, 3>>& H, CellState& st, bool with_tangent = true,
                          const ViscousCell& viscous = {}) {
  const unsigned nq = g.n_q, np = n_pressure_modes(degree);
  st.F.resize(nq);
  st.J.resize(nq);
  st.dV.resize(nq);
  st.S.resize(nq);
  st.CC.resize(nq);
  st.M_inv.reinit(np, np);
  st.K_JJ.reinit(np, np);
  st.M.reinit(np, np);
  st.Np.resize(nq);
  for (std::vector<double>& modes : st.Np) modes.resize(np);
  const dealii::Tensor<2, 3> I = dealii::unit_symmetric_tensor<3>();
  const std::vector<dealii::Point<2>>& unit_points = *g.unit_points;
  dealii::FullMatrix<double>& M = st.M;
  std::array<double, kMaxPressureModes> bJ{}, bp{}, cJ{}, cp{};
  for (unsigned q = 0; q < nq; ++q) {
    st.F[q] = I + H[q];
    st.J[q] = dealii::determinant(st.F[q]);
    if (!(st.J[q] > 0.0) || !std::isfinite(st.J[q])) return false;
    st.dV[q] = kTwoPi * g.R_m[q] * g.JxW_m2[q];
    for (unsigned a = 0; a < np; ++a) st.Np[q][a] = pressure_mode(a, unit_points[q]);
    for (unsigned a = 0; a < np; ++a) {
      bJ[a] += st.Np[q][a] * st.J[q] * st.dV[q];
      for (unsigned b = 0; b < np; ++b) M(a, b) += st.Np[q][a] * st.Np[q][b] * st.dV[q];
    }
  }
  st.M_inv.invert(M);
  for (unsigned a = 0; a < np; ++a)
    for (unsigned b = 0; b < np; ++b) cJ[a] += st.M_inv(a, b) * bJ[b];
  const VolumetricLaw& vol = material.volumetric();
  std::array<double, kMaxQuadraturePoints> J_tilde{}, pressure{};
  for (unsigned q = 0; q < nq; ++q) {
    for (unsigned a = 0; a < np; ++a) J_tilde[q] += cJ[a] * st.Np[q][a];
    if (!(J_tilde[q] > 0.0) || !std::isfinite(J_tilde[q])) return false;
    const double dp = vol.dpressure_dJ(J_tilde[q]);
    for (unsigned a = 0; a < np; ++a) {
      bp[a] += st.Np[q][a] * vol.pressure(J_tilde[q]) * st.dV[q];
      for (unsigned b = 0; b < np; ++b) st.K_JJ(a, b) += dp * st.Np[q][a] * st.Np[q][b] * st.dV[q];
    }
  }
  for (unsigned a = 0; a < np; ++a)
    for (unsigned b = 0; b < np; ++b) cp[a] += st.M_inv(a, b) * bp[b];
  for (unsigned q = 0; q < nq; ++q) {
    for (unsigned a = 0; a < np; ++a) pressure[q] += cp[a] * st.Np[q][a];
    const SymTensor2 C = right_cauchy_green(st.F[q]);
    if (viscous.law) {  // long-term law + Prony stresses from the committed history
      const ViscoelasticHistory& h = (*viscous.history)[q];
      if (with_tangent)
        viscous.law->isochoric_stress_and_tangent(C, viscous.dt_s, h, st.S[q], st.CC[q]);
      else
        st.S[q] = viscous.law->isochoric_stress(C, viscous.dt_s, h);
    } else if (with_tangent) {
      material.isochoric_stress_and_tangent(C, st.S[q], st.CC[q]);
    } else {  // residual only: the stress without its tangent
      st.S[q] = material.isochoric_stress(C);
    }
    if (with_tangent)
      add_volumetric_at_fixed_pressure(dealii::invert(C), st.J[q], pressure[q], st.S[q], st.CC[q]);
    else
      st.S[q] += (pressure[q] * st.J[q]) * dealii::invert(C);
    if (!all_finite(st.S[q])) return false;
  }
  return true;
}

/// Displacement gradients H (3x3, R Z theta) at the quadrature points of a
/// cell from a nodal vector u (scratch for one cell at a time; component: per
/// shape function, 0 for u_R and 1 for u_Z). The sums run over the shape
/// functions in the element's order, as FEValuesViews::Scalar's
/// get_function_gradients and get_function_values do.
class DisplacementGradients {
 public:
  DisplacementGradients(unsigned nq, const std::vector<unsigned>& component)
      : component_(component), g_ur_(nq), g_uz_(nq), v_ur_(nq), dof_values_(component.size()) {}
  void compute(const AxisymmetricCellGeometry& g, const dealii::Vector<double>& u,
               std::vector<dealii::Tensor<2, 3>>& H) {
    const unsigned nq = g.n_q, n = g.dofs_per_cell;
    for (unsigned i = 0; i < n; ++i) dof_values_[i] = u(g.dofs[i]);
    for (unsigned q = 0; q < nq; ++q) {
      g_ur_[q] = dealii::Tensor<1, 2>();
      g_uz_[q] = dealii::Tensor<1, 2>();
      v_ur_[q] = 0.0;
    }
    for (unsigned i = 0; i < n; ++i) {
      const double value = dof_values_[i];
      if (value == 0.0) continue;
      if (component_[i] == 0) {
        for (unsigned q = 0; q < nq; ++q) g_ur_[q] += value * g.grad(i, q);
        for (unsigned q = 0; q < nq; ++q) v_ur_[q] += value * g.value(i, q);
      } else {
        for (unsigned q = 0; q < nq; ++q) g_uz_[q] += value * g.grad(i, q);
      }
    }
    for (unsigned q = 0; q < nq; ++q)
      H[q] = axisymmetric_displacement_gradient(g_ur_[q], g_uz_[q], v_ur_[q], g.R_m[q]);
  }

 private:
  std::vector<unsigned> component_;
  std::vector<dealii::Tensor<1, 2>> g_ur_, g_uz_;
  std::vector<double> v_ur_;
  std::vector<double> dof_values_;
};

}  // namespace puncture::fem::axisymmetric_cell
