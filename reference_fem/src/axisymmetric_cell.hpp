// axisymmetric_cell.hpp: the constitutive state of one cell of the
// axisymmetric solver, shared by its assembly (axisymmetric_solver.cc) and
// its output (axisymmetric_solver_output.cc). Internal to reference_fem/src
// (not part of the public headers).
//
// In:  a cell's FEValues<2> (values, gradients, quadrature points, JxW) and a
//      nodal displacement vector (u_R, u_Z in m); the layer's LayerMaterial
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
#include <deal.II/fe/fe_values_extractors.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>

#include <cmath>
#include <vector>

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
};

/// A viscoelastic cell's law, its points' committed histories and the step
/// (law nullptr: elastic).
struct ViscousCell {
  const ViscoelasticMaterial<LayerMaterial>* law = nullptr;
  const std::vector<ViscoelasticHistory>* history = nullptr;
  double dt_s = 0.0;
};

/// Evaluates st at the cell of fev from the displacement gradients H at its
/// points (with_tangent: also CC and K_JJ); false if a point is inverted or
/// its stress non-finite.
inline bool evaluate_cell(const LayerMaterial& material, unsigned degree, const dealii::FEValues<2>& fev,
                          const std::vector<dealii::Tensor<2, 3>>& H, CellState& st, bool with_tangent = true,
                          const ViscousCell& viscous = {}) {
  const unsigned nq = fev.n_quadrature_points, np = n_pressure_modes(degree);
  st.F.resize(nq);
  st.J.resize(nq);
  st.dV.resize(nq);
  st.S.resize(nq);
  st.CC.resize(nq);
  st.M_inv.reinit(np, np);
  st.K_JJ.reinit(np, np);
  st.Np.assign(nq, std::vector<double>(np, 0.0));
  const dealii::Tensor<2, 3> I = dealii::unit_symmetric_tensor<3>();
  const auto& unit_points = fev.get_quadrature().get_points();
  dealii::FullMatrix<double> M(np, np);
  std::vector<double> bJ(np, 0.0), bp(np, 0.0), cJ(np, 0.0), cp(np, 0.0);
  for (unsigned q = 0; q < nq; ++q) {
    st.F[q] = I + H[q];
    st.J[q] = dealii::determinant(st.F[q]);
    if (!(st.J[q] > 0.0) || !std::isfinite(st.J[q])) return false;
    st.dV[q] = kTwoPi * fev.quadrature_point(q)[0] * fev.JxW(q);
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
  std::vector<double> J_tilde(nq, 0.0), pressure(nq, 0.0);
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
/// cell from a nodal vector u (scratch for one cell at a time).
class DisplacementGradients {
 public:
  explicit DisplacementGradients(unsigned nq) : g_ur_(nq), g_uz_(nq), v_ur_(nq) {}
  void compute(const dealii::FEValues<2>& fev, const dealii::Vector<double>& u,
               std::vector<dealii::Tensor<2, 3>>& H) {
    fev[ur_].get_function_gradients(u, g_ur_);
    fev[uz_].get_function_gradients(u, g_uz_);
    fev[ur_].get_function_values(u, v_ur_);
    for (unsigned q = 0; q < H.size(); ++q)
      H[q] = axisymmetric_displacement_gradient(g_ur_[q], g_uz_[q], v_ur_[q], fev.quadrature_point(q)[0]);
  }

 private:
  const dealii::FEValuesExtractors::Scalar ur_{0}, uz_{1};
  std::vector<dealii::Tensor<1, 2>> g_ur_, g_uz_;
  std::vector<double> v_ur_;
};

}  // namespace puncture::fem::axisymmetric_cell
