// Strain-stiffening laws (Ogden, Veronda-Westmann): stress and tangent against
// central finite differences of the energy, the uniaxial Cauchy stress of a
// nearly incompressible specimen against the incompressible closed forms, the
// neo-Hookean limit of Ogden (alpha = 2), hard cases (alpha up to 20 at large
// stretch, nu = 0.499) and invalid parameters.
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include <puncture/fem/hyperelastic_materials.hpp>

using namespace dealii;
using namespace puncture;
using namespace puncture::fem;

namespace {

SymTensor2 cauchy_green(const Tensor<2, 3>& F) { return symmetrize(transpose(F) * F); }

double total_energy(const LayerMaterial& m, const Tensor<2, 3>& F) {
  return m.isochoric_energy(cauchy_green(F)) + m.volumetric().energy(determinant(F));
}

void total_stress_tangent(const LayerMaterial& m, const Tensor<2, 3>& F, SymTensor2& S, SymTensor4& CC) {
  const SymTensor2 C = cauchy_green(F);
  const SymTensor2 C_inv = invert(C);
  const double J = determinant(F);
  m.isochoric_stress_and_tangent(C, S, CC);
  add_volumetric_at_fixed_pressure(C_inv, J, m.volumetric().pressure(J), S, CC);
  CC += J * J * m.volumetric().dpressure_dJ(J) * outer_product(C_inv, C_inv);
}

Tensor<2, 3> first_piola(const LayerMaterial& m, const Tensor<2, 3>& F) {
  SymTensor2 S;
  SymTensor4 CC;
  total_stress_tangent(m, F, S, CC);
  return F * Tensor<2, 3>(S);
}

Tensor<2, 3> general_deformation(double a) {
  Tensor<2, 3> F;
  const double v[3][3] = {{1.15, 0.22, -0.05}, {-0.1, 0.87, 0.18}, {0.07, 0.12, 1.08}};
  for (unsigned i = 0; i < 3; ++i)
    for (unsigned j = 0; j < 3; ++j) F[i][j] = (i == j ? 1.0 : 0.0) + a * (v[i][j] - (i == j));
  return F;
}

ContinuumMaterial ogden(double E, double nu, std::vector<OgdenTerm> terms) {
  ContinuumMaterial m;
  m.model = "ogden";
  m.youngs_modulus_Pa = E;
  m.poisson_ratio = nu;
  m.ogden_terms = std::move(terms);
  return m;
}

ContinuumMaterial veronda_westmann(double E, double nu, double gamma) {
  ContinuumMaterial m;
  m.model = "veronda_westmann";
  m.youngs_modulus_Pa = E;
  m.poisson_ratio = nu;
  m.veronda_westmann_gamma = gamma;
  return m;
}

/// P = dPsi/dF and A = dP/dF (from S and CC) against central differences,
/// relative to the largest entry of each at that F.
void check_by_finite_differences(const LayerMaterial& m, const Tensor<2, 3>& F, double h, double rel_tol) {
  ASSERT_GT(determinant(F), 0.0);
  const Tensor<2, 3> P = first_piola(m, F);
  // Scales: the largest entry, but at least the modulus (finite differences of
  // the energy carry a round-off of order eps x Psi / h where P vanishes).
  double P_scale = m.youngs_modulus_Pa();
  for (unsigned i = 0; i < 3; ++i)
    for (unsigned J = 0; J < 3; ++J) P_scale = std::max(P_scale, std::abs(P[i][J]));
  SymTensor2 S;
  SymTensor4 CC;
  total_stress_tangent(m, F, S, CC);
  double A_scale = m.youngs_modulus_Pa();
  Tensor<4, 3> A, A_fd;
  for (unsigned k = 0; k < 3; ++k)
    for (unsigned L = 0; L < 3; ++L) {
      Tensor<2, 3> Fp = F, Fm = F;
      Fp[k][L] += h;
      Fm[k][L] -= h;
      const double dpsi = (total_energy(m, Fp) - total_energy(m, Fm)) / (2 * h);
      EXPECT_NEAR(P[k][L], dpsi, rel_tol * P_scale) << "P[" << k << "][" << L << "]";
      const Tensor<2, 3> dP = (first_piola(m, Fp) - first_piola(m, Fm)) / (2 * h);
      for (unsigned i = 0; i < 3; ++i)
        for (unsigned J = 0; J < 3; ++J) {
          double a = (i == k ? S[J][L] : 0.0);
          for (unsigned a2 = 0; a2 < 3; ++a2)
            for (unsigned n = 0; n < 3; ++n) a += F[i][a2] * CC[a2][J][L][n] * F[k][n];
          A[i][J][k][L] = a;
          A_fd[i][J][k][L] = dP[i][J];
          A_scale = std::max(A_scale, std::abs(a));
        }
    }
  for (unsigned i = 0; i < 3; ++i)
    for (unsigned J = 0; J < 3; ++J)
      for (unsigned k = 0; k < 3; ++k)
        for (unsigned L = 0; L < 3; ++L)
          EXPECT_NEAR(A[i][J][k][L], A_fd[i][J][k][L], rel_tol * A_scale)
              << "A[" << i << "][" << J << "][" << k << "][" << L << "]";
}

/// A uniaxial stress state of the (compressible) law: F = diag(l, t, t) with
/// the lateral stretch t found so that the lateral Cauchy stress vanishes
/// (bisection on the law's own stress).
struct UniaxialState {
  double sigma_axial_Pa;
  double lateral_stretch;
  double J;
};

UniaxialState uniaxial_state(const LayerMaterial& m, double stretch) {
  auto sigma = [&](double t) {
    Tensor<2, 3> F;
    F[0][0] = stretch;
    F[1][1] = F[2][2] = t;
    const Tensor<2, 3> P = first_piola(m, F);
    return (1.0 / determinant(F)) * P * transpose(F);
  };
  const double t0 = 1.0 / std::sqrt(stretch);  // incompressible guess
  double lo = 0.2 * t0, hi = 3.0 * t0;
  double f_lo = sigma(lo)[1][1];
  EXPECT_LT(f_lo * sigma(hi)[1][1], 0.0) << "lateral stress not bracketed at stretch " << stretch;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    const double f = sigma(mid)[1][1];
    if ((f < 0) == (f_lo < 0)) {
      lo = mid;
      f_lo = f;
    } else {
      hi = mid;
    }
  }
  const double t = 0.5 * (lo + hi);
  return {sigma(t)[0][0], t, stretch * t * t};
}

}  // namespace

TEST(StiffeningMaterials, OgdenStressAndTangentMatchFiniteDifferences) {
  const LayerMaterial one_term(ogden(3.5e4, 0.45, {{1.0, 9.0}}));
  const LayerMaterial two_terms(ogden(2e4, 0.4, {{0.7, 2.0}, {0.3, 12.0}}));
  const LayerMaterial negative_alpha(ogden(2e4, 0.45, {{1.2, 3.0}, {-0.2, -2.0}}));
  for (const LayerMaterial* m : {&one_term, &two_terms, &negative_alpha})
    for (double a : {0.3, 1.0}) check_by_finite_differences(*m, general_deformation(a), 1e-7, 2e-5);
}

TEST(StiffeningMaterials, OgdenTangentIsSmoothThroughRepeatedStretches) {
  // Equal principal stretches (the reference state, uniaxial and equibiaxial
  // states) make the spectral divided differences degenerate.
  const LayerMaterial m(ogden(3.5e4, 0.45, {{1.0, 9.0}}));
  Tensor<2, 3> uniaxial;
  uniaxial[0][0] = 1.3;
  uniaxial[1][1] = uniaxial[2][2] = 0.88;
  Tensor<2, 3> near_identity = unit_symmetric_tensor<3>();
  near_identity[0][1] = 1e-9;
  for (const Tensor<2, 3>& F : {Tensor<2, 3>(unit_symmetric_tensor<3>()), uniaxial, near_identity})
    check_by_finite_differences(m, F, 1e-6, 2e-5);
}

TEST(StiffeningMaterials, VerondaWestmannStressAndTangentMatchFiniteDifferences) {
  for (double gamma : {0.5, 4.0})
    for (double a : {0.3, 1.0})
      check_by_finite_differences(LayerMaterial(veronda_westmann(3e4, 0.45, gamma)), general_deformation(a), 1e-7,
                                  2e-5);
}

TEST(StiffeningMaterials, OgdenWithAlphaTwoIsNeoHookean) {
  ContinuumMaterial nh;
  nh.model = "neo_hookean";
  nh.youngs_modulus_Pa = 4e4;
  nh.poisson_ratio = 0.47;
  const LayerMaterial a(nh), b(ogden(4e4, 0.47, {{1.0, 2.0}}));
  for (double s : {0.2, 0.9}) {
    const Tensor<2, 3> F = general_deformation(s);
    EXPECT_NEAR(total_energy(a, F), total_energy(b, F), 1e-9 * 4e4);
    const Tensor<2, 3> Pa = first_piola(a, F), Pb = first_piola(b, F);
    EXPECT_LT((Pa - Pb).norm(), 1e-8 * Pa.norm());
  }
}

TEST(StiffeningMaterials, OgdenUniaxialStressMatchesClosedForm) {
  // One-term Ogden in uniaxial stress. Decoupled law, exact at any J:
  //   sigma_11 - sigma_22 = 2 mu / (alpha J) (lbar_1^alpha - lbar_2^alpha),
  // lbar = J^(-1/3) x principal stretch; with sigma_22 = 0 this is sigma_11.
  // Incompressible limit (Ogden 1972; Shergold, Fleck & Radford 2006):
  //   sigma = 2 mu / alpha (lambda^alpha - lambda^(-alpha/2)),
  // met by nu = 0.49999 to the order sigma / kappa.
  for (double nu : {0.45, 0.49999}) {
    const double E = 3.5e4, mu = E / (2 * (1 + nu)), kappa = E / (3 * (1 - 2 * nu));
    for (double alpha : {2.0, 9.0, 20.0}) {
      const LayerMaterial m(ogden(E, nu, {{1.0, alpha}}));
      for (double stretch : {0.6, 0.85, 1.1, 1.5, 2.0}) {
        const UniaxialState u = uniaxial_state(m, stretch);
        const double l1 = stretch * std::cbrt(1.0 / u.J), l2 = u.lateral_stretch * std::cbrt(1.0 / u.J);
        const double exact = 2 * mu / (alpha * u.J) * (std::pow(l1, alpha) - std::pow(l2, alpha));
        EXPECT_NEAR(u.sigma_axial_Pa, exact, 1e-6 * std::abs(exact)) << "alpha " << alpha << " stretch " << stretch;
        if (nu < 0.4999) continue;
        const double incompressible = 2 * mu / alpha * (std::pow(stretch, alpha) - std::pow(stretch, -0.5 * alpha));
        EXPECT_NEAR(u.sigma_axial_Pa, incompressible,
                    std::max(2e-3, 3.0 * std::abs(incompressible) / kappa) * std::abs(incompressible))
            << "alpha " << alpha << " stretch " << stretch;
      }
    }
  }
}

TEST(StiffeningMaterials, VerondaWestmannUniaxialStressMatchesClosedForm) {
  // Isotropic invariant law in uniaxial stress (Holzapfel 2000, Eq. 6.126 and
  // 6.101): exact at any J with the isochoric b = diag(lbar_1^2, lbar_2^2, lbar_2^2):
  //   sigma_11 - sigma_22 = 2/J ((Psi_1 + I1 Psi_2)(b_11 - b_22) - Psi_2 (b_11^2 - b_22^2)),
  // Psi_1 = c1 gamma exp(gamma (I1 - 3)), Psi_2 = -c1 gamma / 2; incompressible limit
  //   sigma = 2 (lambda^2 - 1/lambda) (Psi_1 + Psi_2 / lambda), I1 = lambda^2 + 2/lambda.
  for (double nu : {0.45, 0.49999}) {
    const double E = 3e4, mu = E / (2 * (1 + nu)), kappa = E / (3 * (1 - 2 * nu));
    for (double gamma : {0.3, 2.0}) {
      const LayerMaterial m(veronda_westmann(E, nu, gamma));
      const double c1 = mu / gamma, psi2 = -0.5 * c1 * gamma;
      for (double stretch : {0.7, 1.2, 1.6}) {
        const UniaxialState u = uniaxial_state(m, stretch);
        const double b1 = std::pow(stretch * std::cbrt(1.0 / u.J), 2);
        const double b2 = std::pow(u.lateral_stretch * std::cbrt(1.0 / u.J), 2);
        const double I1 = b1 + 2 * b2, psi1 = c1 * gamma * std::exp(gamma * (I1 - 3.0));
        const double exact = 2.0 / u.J * ((psi1 + I1 * psi2) * (b1 - b2) - psi2 * (b1 * b1 - b2 * b2));
        EXPECT_NEAR(u.sigma_axial_Pa, exact, 1e-6 * std::abs(exact)) << "gamma " << gamma << " stretch " << stretch;
        if (nu < 0.4999) continue;
        const double I1i = stretch * stretch + 2.0 / stretch;
        const double incompressible = 2.0 * (stretch * stretch - 1.0 / stretch) *
                                      (c1 * gamma * std::exp(gamma * (I1i - 3.0)) + psi2 / stretch);
        EXPECT_NEAR(u.sigma_axial_Pa, incompressible,
                    std::max(2e-3, 3.0 * std::abs(incompressible) / kappa) * std::abs(incompressible))
            << "gamma " << gamma << " stretch " << stretch;
      }
    }
  }
}

TEST(StiffeningMaterials, StiffeningLawsAgreeWithNeoHookeanAtSmallStrain) {
  // All laws share the initial shear modulus: a 0.1 % uniaxial stretch gives
  // E x strain within 0.5 %.
  const double E = 3.5e4, nu = 0.4999;
  for (const ContinuumMaterial& mat : {ogden(E, nu, {{1.0, 12.0}}), veronda_westmann(E, nu, 3.0)}) {
    const LayerMaterial m(mat);
    EXPECT_NEAR(uniaxial_state(m, 1.001).sigma_axial_Pa, E * 1e-3, 5e-3 * E * 1e-3) << mat.model;
  }
}

TEST(StiffeningMaterials, HardCasesStayFiniteAndConsistent) {
  // Ogden alpha = 20 (adipose tissue at large strain), nu = 0.499, stretches
  // up to 2 in tension and 0.5 in compression: finite stress, tangent
  // consistent with finite differences.
  const LayerMaterial m(ogden(2e3, 0.499, {{1.0, 20.0}}));
  for (double s : {0.5, 1.0, 2.0}) {
    Tensor<2, 3> F;
    F[0][0] = s;
    F[1][1] = F[2][2] = 1.0 / std::sqrt(s);
    F[0][1] = 0.1;
    const Tensor<2, 3> P = first_piola(m, F);
    for (unsigned i = 0; i < 3; ++i)
      for (unsigned j = 0; j < 3; ++j) ASSERT_TRUE(std::isfinite(P[i][j]));
    check_by_finite_differences(m, F, 1e-7 * s, 1e-4);
  }
}

TEST(StiffeningMaterials, RejectsInvalidParameters) {
  EXPECT_THROW(LayerMaterial(ogden(1e4, 0.45, {})), std::invalid_argument);
  EXPECT_THROW(LayerMaterial(ogden(1e4, 0.45, {{1.0, 0.0}})), std::invalid_argument);
  EXPECT_THROW(LayerMaterial(ogden(1e4, 0.45, {{-1.0, 5.0}})), std::invalid_argument);
  EXPECT_THROW(LayerMaterial(veronda_westmann(1e4, 0.45, 0.0)), std::invalid_argument);
  EXPECT_THROW(LayerMaterial(veronda_westmann(1e4, 0.45, -2.0)), std::invalid_argument);
}

// The residual-only path (isochoric_stress, no tangent) of every law: the
// isochoric first Piola stress F S_iso against central differences of the
// isochoric energy in F.
TEST(StiffeningMaterials, StressWithoutTangentIsTheEnergyDerivativeForEveryLaw) {
  ContinuumMaterial neo;
  neo.model = "neo_hookean";
  neo.youngs_modulus_Pa = 3e4;
  neo.poisson_ratio = 0.45;
  ContinuumMaterial mooney = neo;
  mooney.model = "mooney_rivlin";
  mooney.mooney_rivlin_c01_fraction = 0.3;
  const LayerMaterial laws[] = {LayerMaterial(neo), LayerMaterial(mooney),
                                LayerMaterial(ogden(2e4, 0.4, {{0.7, 2.0}, {0.3, 12.0}})),
                                LayerMaterial(veronda_westmann(2e4, 0.45, 1.5))};
  const double h = 1e-7;
  for (const LayerMaterial& m : laws)
    for (double a : {0.3, 1.0}) {
      const Tensor<2, 3> F = general_deformation(a);
      const Tensor<2, 3> P = F * Tensor<2, 3>(m.isochoric_stress(cauchy_green(F)));
      double scale = m.youngs_modulus_Pa();
      for (unsigned i = 0; i < 3; ++i)
        for (unsigned J = 0; J < 3; ++J) scale = std::max(scale, std::abs(P[i][J]));
      for (unsigned k = 0; k < 3; ++k)
        for (unsigned L = 0; L < 3; ++L) {
          Tensor<2, 3> Fp = F, Fm = F;
          Fp[k][L] += h;
          Fm[k][L] -= h;
          const double fd = (m.isochoric_energy(cauchy_green(Fp)) - m.isochoric_energy(cauchy_green(Fm))) / (2 * h);
          EXPECT_NEAR(P[k][L], fd, 2e-5 * scale) << "P[" << k << "][" << L << "] a " << a;
        }
      // The same stress as the stress-and-tangent path.
      SymTensor2 S;
      SymTensor4 CC;
      m.isochoric_stress_and_tangent(cauchy_green(F), S, CC);
      EXPECT_LT((S - m.isochoric_stress(cauchy_green(F))).norm(), 1e-12 * std::max(1.0, S.norm()));
    }
}
