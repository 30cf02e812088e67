// hyperelastic_materials.hpp: the continuum material laws of the FEM reference
// (header-only, in the manner of deal.II step-44: one small class per law).
//
// Every law is written in the reference (material) configuration as a function
// of the right Cauchy-Green tensor C = F^T F (dimensionless, symmetric 3x3):
//   energy(C)   strain energy per unit reference volume, J/m^3 = Pa
//   stress(C)   second Piola-Kirchhoff stress S = 2 dPsi/dC, Pa
//   tangent(C)  material elasticity tensor CC = 4 d^2Psi/dC dC, Pa
//               (minor symmetries; major symmetry holds for these laws)
//
// The strain energy is split (Holzapfel 2000, Sec. 6.4; step-44):
//   Psi(C) = Psi_iso(Cbar) + Psi_vol(J),  Cbar = J^{-2/3} C,  J = sqrt(det C).
// Isochoric laws (mu = initial shear modulus in every case):
//   NeoHookean:      Psi_iso = mu/2 (I1bar - 3)
//   MooneyRivlin:    Psi_iso = c10 (I1bar - 3) + c01 (I2bar - 3),  mu = 2 (c10 + c01)
//   Ogden:           Psi_iso = sum_p 2 mu_p / alpha_p^2 (sum_a lambdabar_a^alpha_p - 3),
//                    mu = sum_p mu_p (Ogden 1972; the normalisation of
//                    Shergold, Fleck & Radford 2006 for skin)
//   VerondaWestmann: Psi_iso = c1 (exp(gamma (I1bar - 3)) - 1) - c1 gamma/2 (I2bar - 3),
//                    mu = c1 gamma (Veronda & Westmann 1970, J. Biomech. 3:111)
// Volumetric law (step-44 and the deal.II code gallery Cook membrane):
//   VolumetricLaw: Psi_vol = kappa/4 (J^2 - 1 - 2 ln J),
//                  kappa = E / (3 (1 - 2 nu)), mu = E / (2 (1 + nu)).
// How the volumetric term enters the finite-element equations (pointwise J, or
// the projected dilatation of the Hu-Washizu three-field formulation) is the
// solver's business (finite_strain_solver.hpp); here it is a function of one
// scalar J (or Jtilde).
#pragma once

#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include <puncture/scene.hpp>

namespace puncture::fem {

using SymTensor2 = dealii::SymmetricTensor<2, 3>;
using SymTensor4 = dealii::SymmetricTensor<4, 3>;

/// (a x b)_{ABCD} = a_AB b_CD, written on the 6 x 6 independent components
/// (the products dealii::outer_product forms one index quadruple at a time).
inline SymTensor4 outer(const SymTensor2& a, const SymTensor2& b) {
  SymTensor4 out;
  const double* pa = a.begin_raw();
  const double* pb = b.begin_raw();
  double* po = out.begin_raw();
  constexpr unsigned n = SymTensor2::n_independent_components;
  for (unsigned I = 0; I < n; ++I)
    for (unsigned K = 0; K < n; ++K) po[n * I + K] = pa[I] * pb[K];
  return out;
}

/// (A (.) A)_{ABCD} = 1/2 (A_AC A_BD + A_AD A_BC): the symmetrised product
/// that appears in d(C^{-1})/dC = -(C^{-1} (.) C^{-1}) (on the 6 x 6
/// independent components).
inline SymTensor4 symmetric_product(const SymTensor2& A) {
  SymTensor4 out;
  const double* pa = A.begin_raw();
  double* po = out.begin_raw();
  // The storage order of the independent components is deal.II's (00, 11, 22, 01, 02, 12 in 3D).
  const auto at = [pa](unsigned i, unsigned j) {
    return pa[SymTensor2::component_to_unrolled_index(dealii::TableIndices<2>(i, j))];
  };
  constexpr unsigned n = SymTensor2::n_independent_components;
  for (unsigned I = 0; I < n; ++I) {
    const dealii::TableIndices<2> ab = SymTensor2::unrolled_to_component_indices(I);
    for (unsigned K = 0; K < n; ++K) {
      const dealii::TableIndices<2> cd = SymTensor2::unrolled_to_component_indices(K);
      po[n * I + K] = 0.5 * (at(ab[0], cd[0]) * at(ab[1], cd[1]) + at(ab[0], cd[1]) * at(ab[1], cd[0]));
    }
  }
  return out;
}

/// Pushes the fictitious stress and tangent of an isochoric law to the
/// isochoric S and CC (Holzapfel 2000, Eq. 6.89 and 6.168):
///   S_iso  = J^{-2/3} Dev(Sbar),  Dev(X) = X - 1/3 (X : C) C^{-1}
///   CC_iso = P : CCbar : P^T + 2/3 Tr(J^{-2/3} Sbar) Ptilde
///            - 2/3 (C^{-1} x S_iso + S_iso x C^{-1})
/// with P = I - 1/3 C^{-1} x C, Ptilde = C^{-1} (.) C^{-1} - 1/3 C^{-1} x C^{-1},
/// CCbar = J^{-4/3} (4 d^2 Psi / dCbar dCbar) = J^{-4/3} CC_hat.
/// In: C, Sbar = 2 dPsi/dCbar, CC_hat (may be null for laws linear in Cbar).
/// The stress part alone: S_iso = J^{-2/3} Dev(Sbar) (no tangent; for
/// residual-only evaluations).
inline SymTensor2 isochoric_stress_push(const SymTensor2& C, const SymTensor2& Sbar) {
  const SymTensor2 C_inv = dealii::invert(C);
  const double J_m23 = std::cbrt(1.0 / dealii::determinant(C));  // J^{-2/3} = det(C)^{-1/3}
  return J_m23 * (Sbar - (dealii::scalar_product(Sbar, C) / 3.0) * C_inv);
}

/// Cbar = J^{-2/3} C.
inline SymTensor2 isochoric_part(const SymTensor2& C) { return std::cbrt(1.0 / dealii::determinant(C)) * C; }

inline void isochoric_push(const SymTensor2& C, const SymTensor2& Sbar, const SymTensor4* CC_hat,
                           SymTensor2& S_iso, SymTensor4& CC_iso) {
  const double J = std::sqrt(dealii::determinant(C));
  const SymTensor2 C_inv = dealii::invert(C);
  const double J_m23 = std::pow(J, -2.0 / 3.0);
  const double Sbar_C = dealii::scalar_product(Sbar, C);  // Tr(Sbar)
  S_iso = J_m23 * (Sbar - (Sbar_C / 3.0) * C_inv);
  const SymTensor4 Cinv_x_Cinv = outer(C_inv, C_inv);
  const SymTensor4 P_tilde = symmetric_product(C_inv) - (1.0 / 3.0) * Cinv_x_Cinv;
  CC_iso = (2.0 / 3.0) * J_m23 * Sbar_C * P_tilde -
           (2.0 / 3.0) * (outer(C_inv, S_iso) + outer(S_iso, C_inv));
  if (CC_hat != nullptr) {
    const SymTensor4 identity = dealii::identity_tensor<3>();
    const SymTensor4 P = identity - (1.0 / 3.0) * outer(C_inv, C);
    const SymTensor4 P_T = identity - (1.0 / 3.0) * outer(C, C_inv);
    CC_iso += std::pow(J, -4.0 / 3.0) * (P * (*CC_hat) * P_T);
  }
}

/// Isochoric compressible neo-Hookean law: Psi_iso = mu/2 (I1bar - 3).
class NeoHookean {
 public:
  explicit NeoHookean(double shear_modulus_Pa) : mu_(shear_modulus_Pa) {
    if (!(mu_ > 0.0)) throw std::invalid_argument("NeoHookean: shear modulus must be > 0");
  }
  double shear_modulus_Pa() const { return mu_; }

  double energy(const SymTensor2& C) const {
    const double J = std::sqrt(dealii::determinant(C));
    return 0.5 * mu_ * (std::pow(J, -2.0 / 3.0) * dealii::trace(C) - 3.0);
  }
  SymTensor2 stress(const SymTensor2& C) const { return isochoric_stress_push(C, fictitious_stress(C)); }
  SymTensor4 tangent(const SymTensor2& C) const {
    SymTensor2 S;
    SymTensor4 CC;
    stress_and_tangent(C, S, CC);
    return CC;
  }
  SymTensor2 fictitious_stress(const SymTensor2& /*C*/) const { return mu_ * dealii::unit_symmetric_tensor<3>(); }
  /// Sbar = mu I; CC_hat = 0.
  void stress_and_tangent(const SymTensor2& C, SymTensor2& S, SymTensor4& CC) const {
    const SymTensor2 Sbar = mu_ * dealii::unit_symmetric_tensor<3>();
    isochoric_push(C, Sbar, nullptr, S, CC);
  }

 private:
  double mu_;  ///< shear modulus, Pa
};

/// Isochoric Mooney-Rivlin law: Psi_iso = c10 (I1bar - 3) + c01 (I2bar - 3),
/// I2bar = 1/2 (I1bar^2 - tr(Cbar^2)); small-strain shear modulus 2 (c10 + c01).
class MooneyRivlin {
 public:
  MooneyRivlin(double c10_Pa, double c01_Pa) : c10_(c10_Pa), c01_(c01_Pa) {
    if (!(c10_ >= 0.0 && c01_ >= 0.0 && c10_ + c01_ > 0.0))
      throw std::invalid_argument("MooneyRivlin: need c10 >= 0, c01 >= 0, c10 + c01 > 0");
  }
  double shear_modulus_Pa() const { return 2.0 * (c10_ + c01_); }

  double energy(const SymTensor2& C) const {
    const double J = std::sqrt(dealii::determinant(C));
    const SymTensor2 Cbar = std::pow(J, -2.0 / 3.0) * C;
    const double I1 = dealii::trace(Cbar);
    const double I2 = 0.5 * (I1 * I1 - dealii::scalar_product(Cbar, Cbar));
    return c10_ * (I1 - 3.0) + c01_ * (I2 - 3.0);
  }
  SymTensor2 stress(const SymTensor2& C) const { return isochoric_stress_push(C, fictitious_stress(C)); }
  SymTensor4 tangent(const SymTensor2& C) const {
    SymTensor2 S;
    SymTensor4 CC;
    stress_and_tangent(C, S, CC);
    return CC;
  }
  /// Sbar = 2 (c10 + c01 I1bar) I - 2 c01 Cbar.
  SymTensor2 fictitious_stress(const SymTensor2& C) const {
    const SymTensor2 Cbar = isochoric_part(C);
    return 2.0 * (c10_ + c01_ * dealii::trace(Cbar)) * dealii::unit_symmetric_tensor<3>() - 2.0 * c01_ * Cbar;
  }
  /// Sbar as above;  CC_hat = 4 c01 (I x I - II).
  void stress_and_tangent(const SymTensor2& C, SymTensor2& S, SymTensor4& CC) const {
    const SymTensor2 I = dealii::unit_symmetric_tensor<3>();
    const SymTensor2 Sbar = fictitious_stress(C);
    const SymTensor4 CC_hat =
        4.0 * c01_ * (dealii::outer_product(I, I) - dealii::identity_tensor<3>());
    isochoric_push(C, Sbar, &CC_hat, S, CC);
  }

 private:
  double c10_;  ///< Pa
  double c01_;  ///< Pa
};

/// Derivative of a spectral (isotropic) function of a symmetric tensor by the
/// Daleckii-Krein formula. For G(X) = sum_a g(x_a) N_a (x) N_a (x_a, N_a the
/// eigenvalues and eigenvectors of X):
///   dG/dX = sum_{a,b} theta_ab (N_a (x) N_b) (x) (N_a (x) N_b)  (symmetrised),
///   theta_aa = g'(x_a),  theta_ab = (g(x_a) - g(x_b)) / (x_a - x_b),
/// with the divided difference replaced by g' at the mean where two
/// eigenvalues (nearly) coincide, so the result is smooth through repeated
/// eigenvalues (e.g. the undeformed state).
/// G(X) = sum_a g(x_a) N_a (x) N_a alone (no derivative).
template <class G>
SymTensor2 spectral_value(const SymTensor2& X, const G& g) {
  const auto eig = dealii::eigenvectors(X, dealii::SymmetricTensorEigenvectorMethod::jacobi);
  SymTensor2 value;
  for (unsigned a = 0; a < 3; ++a) {
    const double ga = g(eig[a].first);
    for (unsigned i = 0; i < 3; ++i)
      for (unsigned j = i; j < 3; ++j) value[i][j] += ga * eig[a].second[i] * eig[a].second[j];
  }
  return value;
}

template <class G, class DG>
void spectral_function(const SymTensor2& X, const G& g, const DG& dg, SymTensor2& value, SymTensor4& derivative) {
  const auto eig = dealii::eigenvectors(X, dealii::SymmetricTensorEigenvectorMethod::jacobi);
  double x[3], gx[3];
  dealii::Tensor<1, 3> N[3];
  for (unsigned a = 0; a < 3; ++a) {
    x[a] = eig[a].first;
    N[a] = eig[a].second;
    gx[a] = g(x[a]);
  }
  double theta[3][3];
  for (unsigned a = 0; a < 3; ++a)
    for (unsigned b = 0; b < 3; ++b) {
      const double d = x[a] - x[b];
      theta[a][b] = (a == b || std::abs(d) <= 1e-6 * std::max(1.0, std::abs(x[a])))
                        ? dg(0.5 * (x[a] + x[b]))
                        : (gx[a] - gx[b]) / d;
    }
  value = SymTensor2();
  derivative = SymTensor4();
  for (unsigned a = 0; a < 3; ++a)
    for (unsigned i = 0; i < 3; ++i)
      for (unsigned j = i; j < 3; ++j) value[i][j] += gx[a] * N[a][i] * N[a][j];
  for (unsigned i = 0; i < 3; ++i)
    for (unsigned j = i; j < 3; ++j)
      for (unsigned k = 0; k < 3; ++k)
        for (unsigned l = k; l < 3; ++l) {
          double s = 0.0;
          for (unsigned a = 0; a < 3; ++a)
            for (unsigned b = 0; b < 3; ++b)
              s += theta[a][b] * 0.5 * (N[a][i] * N[b][j] + N[b][i] * N[a][j]) * 0.5 *
                   (N[a][k] * N[b][l] + N[b][k] * N[a][l]);
          derivative[i][j][k][l] = s;
        }
}

/// Isochoric N-term Ogden law (strain-stiffening for alpha > 2):
///   Psi_iso = sum_p 2 mu_p / alpha_p^2 (sum_a cbar_a^(alpha_p/2) - 3),
/// cbar_a the eigenvalues of Cbar (squared isochoric principal stretches).
/// Initial shear modulus sum_p mu_p; alpha = 2 (one term) is neo-Hookean.
/// Sbar = 2 dPsi/dCbar = sum_a g(cbar_a) N_a (x) N_a with
/// g(c) = sum_p 2 mu_p / alpha_p c^(alpha_p/2 - 1); CC_hat = 2 dSbar/dCbar
/// by the spectral derivative above.
class Ogden {
 public:
  struct Term {
    double mu_Pa;  ///< mu_p (mu_p alpha_p > 0)
    double alpha;  ///< alpha_p (nonzero)
  };
  explicit Ogden(std::vector<Term> terms) : terms_(std::move(terms)) {
    if (terms_.empty()) throw std::invalid_argument("Ogden: at least one term");
    double mu = 0.0;
    for (const Term& t : terms_) {
      if (!(std::abs(t.alpha) > 0.0) || !std::isfinite(t.alpha) || !(t.mu_Pa * t.alpha > 0.0))
        throw std::invalid_argument("Ogden: every term needs alpha != 0 and mu alpha > 0");
      mu += t.mu_Pa;
    }
    if (!(mu > 0.0)) throw std::invalid_argument("Ogden: initial shear modulus must be > 0");
  }
  double shear_modulus_Pa() const {
    double mu = 0.0;
    for (const Term& t : terms_) mu += t.mu_Pa;
    return mu;
  }

  double energy(const SymTensor2& C) const {
    const double J = std::sqrt(dealii::determinant(C));
    const auto c = dealii::eigenvalues(std::pow(J, -2.0 / 3.0) * C);
    double psi = 0.0;
    for (const Term& t : terms_) {
      double sum = -3.0;
      for (unsigned a = 0; a < 3; ++a) sum += std::pow(c[a], 0.5 * t.alpha);
      psi += 2.0 * t.mu_Pa / (t.alpha * t.alpha) * sum;
    }
    return psi;
  }
  /// g(c) = sum_p 2 mu_p / alpha_p c^(alpha_p/2 - 1) (Sbar = sum_a g(cbar_a) N_a (x) N_a).
  double principal_stress(double c) const {
    double v = 0.0;
    for (const Term& t : terms_) v += 2.0 * t.mu_Pa / t.alpha * std::pow(c, 0.5 * t.alpha - 1.0);
    return v;
  }
  SymTensor2 fictitious_stress(const SymTensor2& C) const {
    return spectral_value(isochoric_part(C), [this](double c) { return principal_stress(c); });
  }
  SymTensor2 stress(const SymTensor2& C) const { return isochoric_stress_push(C, fictitious_stress(C)); }
  void stress_and_tangent(const SymTensor2& C, SymTensor2& S, SymTensor4& CC) const {
    const SymTensor2 Cbar = isochoric_part(C);
    auto g = [this](double c) { return principal_stress(c); };
    auto dg = [this](double c) {
      double v = 0.0;
      for (const Term& t : terms_)
        v += 2.0 * t.mu_Pa / t.alpha * (0.5 * t.alpha - 1.0) * std::pow(c, 0.5 * t.alpha - 2.0);
      return v;
    };
    SymTensor2 Sbar;
    SymTensor4 dSbar;
    spectral_function(Cbar, g, dg, Sbar, dSbar);
    const SymTensor4 CC_hat = 2.0 * dSbar;
    isochoric_push(C, Sbar, &CC_hat, S, CC);
  }

 private:
  std::vector<Term> terms_;
};

/// Isochoric Veronda-Westmann law (exponential stiffening in I1bar):
///   Psi_iso = c1 (exp(gamma (I1bar - 3)) - 1) - c1 gamma / 2 (I2bar - 3),
/// initial shear modulus mu = c1 gamma. With Psi_1 = c1 gamma e, Psi_11 =
/// c1 gamma^2 e (e = exp(gamma (I1bar - 3))) and Psi_2 = -c1 gamma / 2:
///   Sbar   = 2 (Psi_1 + I1bar Psi_2) I - 2 Psi_2 Cbar,
///   CC_hat = 4 ((Psi_11 + Psi_2) I x I - Psi_2 II).
class VerondaWestmann {
 public:
  VerondaWestmann(double shear_modulus_Pa, double gamma) : c1_(shear_modulus_Pa / gamma), gamma_(gamma) {
    if (!(shear_modulus_Pa > 0.0) || !(gamma > 0.0) || !std::isfinite(gamma))
      throw std::invalid_argument("VerondaWestmann: need shear modulus > 0 and gamma > 0");
  }
  double shear_modulus_Pa() const { return c1_ * gamma_; }

  double energy(const SymTensor2& C) const {
    const double J = std::sqrt(dealii::determinant(C));
    const SymTensor2 Cbar = std::pow(J, -2.0 / 3.0) * C;
    const double I1 = dealii::trace(Cbar);
    const double I2 = 0.5 * (I1 * I1 - dealii::scalar_product(Cbar, Cbar));
    return c1_ * (std::exp(gamma_ * (I1 - 3.0)) - 1.0) - 0.5 * c1_ * gamma_ * (I2 - 3.0);
  }
  SymTensor2 fictitious_stress(const SymTensor2& C) const {
    const SymTensor2 Cbar = isochoric_part(C);
    const double I1 = dealii::trace(Cbar);
    const double psi1 = c1_ * gamma_ * std::exp(gamma_ * (I1 - 3.0)), psi2 = -0.5 * c1_ * gamma_;
    return 2.0 * (psi1 + I1 * psi2) * dealii::unit_symmetric_tensor<3>() - 2.0 * psi2 * Cbar;
  }
  SymTensor2 stress(const SymTensor2& C) const { return isochoric_stress_push(C, fictitious_stress(C)); }
  void stress_and_tangent(const SymTensor2& C, SymTensor2& S, SymTensor4& CC) const {
    const SymTensor2 Cbar = isochoric_part(C);
    const SymTensor2 I = dealii::unit_symmetric_tensor<3>();
    const double I1 = dealii::trace(Cbar);
    const double e = std::exp(gamma_ * (I1 - 3.0));
    const double psi1 = c1_ * gamma_ * e, psi11 = c1_ * gamma_ * gamma_ * e, psi2 = -0.5 * c1_ * gamma_;
    const SymTensor2 Sbar = 2.0 * (psi1 + I1 * psi2) * I - 2.0 * psi2 * Cbar;
    const SymTensor4 CC_hat =
        4.0 * ((psi11 + psi2) * dealii::outer_product(I, I) - psi2 * dealii::identity_tensor<3>());
    isochoric_push(C, Sbar, &CC_hat, S, CC);
  }

 private:
  double c1_;     ///< Pa
  double gamma_;  ///< dimensionless
};

/// Volumetric energy Psi_vol(J) = kappa/4 (J^2 - 1 - 2 ln J) (step-44). Its
/// pressure p = dPsi/dJ = kappa/2 (J - 1/J) and stiffness d2Psi/dJ2 =
/// kappa/2 (1 + 1/J^2) stay finite for every J > 0 and grow without bound as
/// J -> 0, so a compressed element resists inversion.
class VolumetricLaw {
 public:
  explicit VolumetricLaw(double bulk_modulus_Pa) : kappa_(bulk_modulus_Pa) {
    if (!(kappa_ > 0.0)) throw std::invalid_argument("VolumetricLaw: bulk modulus must be > 0");
  }
  double bulk_modulus_Pa() const { return kappa_; }
  double energy(double J) const { return 0.25 * kappa_ * (J * J - 1.0 - 2.0 * std::log(J)); }
  double pressure(double J) const { return 0.5 * kappa_ * (J - 1.0 / J); }  ///< Pa
  double dpressure_dJ(double J) const { return 0.5 * kappa_ * (1.0 + 1.0 / (J * J)); }  ///< Pa

 private:
  double kappa_;  ///< bulk modulus, Pa
};

/// The material of one layer: an isochoric law plus the volumetric law, built
/// from the scene's ContinuumMaterial (E, nu, model, Mooney-Rivlin C01 share).
class LayerMaterial {
 public:
  explicit LayerMaterial(const ContinuumMaterial& m)
      : iso_(make_isochoric(m)), vol_(bulk_modulus(m)), youngs_modulus_Pa_(m.youngs_modulus_Pa),
        poisson_ratio_(m.poisson_ratio) {}

  static double shear_modulus(const ContinuumMaterial& m) {
    check(m);
    return m.youngs_modulus_Pa / (2.0 * (1.0 + m.poisson_ratio));
  }
  static double bulk_modulus(const ContinuumMaterial& m) {
    check(m);
    return m.youngs_modulus_Pa / (3.0 * (1.0 - 2.0 * m.poisson_ratio));
  }

  double youngs_modulus_Pa() const { return youngs_modulus_Pa_; }
  double poisson_ratio() const { return poisson_ratio_; }
  const VolumetricLaw& volumetric() const { return vol_; }

  double isochoric_energy(const SymTensor2& C) const {
    return std::visit([&](const auto& law) { return law.energy(C); }, iso_);
  }
  void isochoric_stress_and_tangent(const SymTensor2& C, SymTensor2& S, SymTensor4& CC) const {
    std::visit([&](const auto& law) { law.stress_and_tangent(C, S, CC); }, iso_);
  }
  /// S_iso alone (residual-only evaluations skip the tangent).
  SymTensor2 isochoric_stress(const SymTensor2& C) const {
    return std::visit([&](const auto& law) { return law.stress(C); }, iso_);
  }

 private:
  static void check(const ContinuumMaterial& m) {
    if (!(m.youngs_modulus_Pa > 0.0) || !std::isfinite(m.youngs_modulus_Pa))
      throw std::invalid_argument("material: Young's modulus must be > 0");
    if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5))
      throw std::invalid_argument("material: Poisson's ratio must lie in (-1, 0.5)");
  }
  static std::variant<NeoHookean, MooneyRivlin, Ogden, VerondaWestmann> make_isochoric(
      const ContinuumMaterial& m) {
    const double mu = shear_modulus(m);
    if (m.model == "neo_hookean") return NeoHookean(mu);
    if (m.model == "mooney_rivlin") {
      const double f = m.mooney_rivlin_c01_fraction;
      if (!(f >= 0.0 && f <= 1.0))
        throw std::invalid_argument("material: mooney_rivlin_c01_fraction must lie in [0, 1]");
      return MooneyRivlin(0.5 * mu * (1.0 - f), 0.5 * mu * f);
    }
    if (m.model == "ogden") {
      std::vector<Ogden::Term> terms;
      for (const OgdenTerm& t : m.ogden_terms) terms.push_back({t.mu_fraction * mu, t.alpha});
      return Ogden(terms);
    }
    if (m.model == "veronda_westmann") return VerondaWestmann(mu, m.veronda_westmann_gamma);
    throw std::invalid_argument("material: unknown model '" + m.model +
                                "' (expected neo_hookean, mooney_rivlin, ogden or veronda_westmann)");
  }

  std::variant<NeoHookean, MooneyRivlin, Ogden, VerondaWestmann> iso_;
  VolumetricLaw vol_;
  double youngs_modulus_Pa_;
  double poisson_ratio_;
};

/// Volumetric contribution at fixed pressure p (Pa) to S and CC:
///   S_vol = p J C^{-1},  CC_vol = p J (C^{-1} x C^{-1} - 2 C^{-1} (.) C^{-1}).
/// With p = dPsi_vol/dJ evaluated pointwise (one-field formulation) the full
/// volumetric tangent adds J^2 d2Psi/dJ2 C^{-1} x C^{-1}.
inline void add_volumetric_at_fixed_pressure(const SymTensor2& C_inv, double J, double p,
                                             SymTensor2& S, SymTensor4& CC) {
  S += (p * J) * C_inv;
  CC += (p * J) * (outer(C_inv, C_inv) - 2.0 * symmetric_product(C_inv));
}

}  // namespace puncture::fem
