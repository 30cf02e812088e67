// viscoelastic_material.hpp: finite-strain viscoelasticity with a Prony series
// on the isochoric part (header-only, in the manner of deal.II step-44 and of
// hyperelastic_materials.hpp: parameters, per-point state, stress, tangent).
//
// The model of Simo (1987) in the form of Holzapfel (2000), Sec. 6.10
// ("finite linear viscoelasticity"):
//   Psi = Psi_vol(J) + Psi_iso^inf(Cbar) + sum_i Upsilon_i(Cbar, Gamma_i).
// The wrapped elastic laws are the LONG-TERM (fully relaxed, equilibrium)
// response: any isochoric law of hyperelastic_materials.hpp (NeoHookean,
// MooneyRivlin, Ogden, VerondaWestmann, or a LayerMaterial, which dispatches
// over its variant) plus the elastic VolumetricLaw. Each Prony term i adds a
// non-equilibrium stress Q_i (Pa) driven by the long-term isochoric stress
// S_iso^inf = 2 dPsi_iso^inf/dC (isochoric_push, Holzapfel Eq. 6.89):
//   dQ_i/dt + Q_i / tau_i = beta_i d(S_iso^inf)/dt,
//   Q_i(t) = int_{-inf}^{t} beta_i exp(-(t - s)/tau_i) d(S_iso^inf)/ds ds,
// so S = S_vol + S_iso^inf + sum_i Q_i. The bulk response stays elastic.
//
// Time integration (Holzapfel 2000, Sec. 6.10; Simo 1987, Comput. Methods
// Appl. Mech. Engrg. 60:153-173):
// the hereditary integral over one step [t_n, t_n + dt] by the midpoint rule
// for the kernel, xi_i = -dt / (2 tau_i):
//   H_i       = exp(xi_i) (exp(xi_i) Q_i^n - beta_i S_iso^{inf,n})
//   Q_i^{n+1} = H_i + beta_i exp(xi_i) S_iso^{inf,n+1}
// (the form also used by H. Narayanan's public Holzapfel-Ogden myocardium
// scripts, xi = -dt/(2 tau)). It is second-order
// accurate in dt, exact whenever S_iso^inf is constant over the step (a held
// strain relaxes exactly for any dt) and unconditionally stable. The history
// (Q_i^n, S_iso^{inf,n}) is frozen during a step, so the consistent
// algorithmic tangent is exact (Holzapfel 2000, Sec. 6.10):
//   CC = CC_vol + (1 + delta) CC_iso^inf,  delta = sum_i beta_i exp(xi_i).
//
// Parameters. beta_i >= 0 (dimensionless) is the free-energy factor of term i
// RELATIVE TO THE LONG-TERM law: after a sudden isochoric strain, held, the
// isochoric stress is S_iso^inf (1 + sum_i beta_i exp(-t/tau_i)); the
// instantaneous shear modulus is (1 + sum beta_i) x the long-term one. The
// normalised relaxation function (what a hold in an indentation or insertion
// measures, and the small-strain G(t)/G(0)) is
//   g(t) = (1 + sum_i beta_i exp(-t/tau_i)) / (1 + sum_i beta_i),
// g(0) = 1; the RELAXED FRACTION g(inf) = 1 / (1 + sum_i beta_i) is the
// fraction of the instantaneous isochoric stress left when everything has
// relaxed (relaxed fraction 0.6 = "relaxes by 40 %"). Fits reported in the
// normalised Prony form g(t) = 1 - sum_i g_i (1 - exp(-t/tau_i)) (Abaqus,
// FEBio, puncture::comparison::PronySeries) convert by
// beta_i = g_i / (1 - sum_j g_j): prony_terms_from_normalised below.
// If a layer's measured modulus is the instantaneous one, the wrapped law
// needs that modulus divided by (1 + sum beta_i).
//
// Limits (documented, not hidden): Q_i lives in the reference configuration
// and is not re-projected onto the current deviatoric space, so at large
// strain it is not exactly deviatoric (the known property of this "finite
// linear" model; Holzapfel 2000, Sec. 6.10; Liu, Latorre & Marsden, "A
// continuum and computational framework for viscoelastodynamics", Part III,
// arXiv:2405.03090, discuss it). For held or slowly varying
// strains (relaxation during a needle dwell) the relaxation is exact, see the
// tests.
//
// Use at a quadrature point: keep one ViscoelasticHistory (initial_history()
// = undisturbed past); during the Newton iterations of a step of length dt
// call stress_and_tangent(C, dt, history, S, CC) (the history is only read);
// when the step has converged call commit(C, dt, history) once with the
// converged C. A three-field (u-p-Jtilde) solver takes the isochoric part
// alone (isochoric_stress_and_tangent) and adds its own volumetric terms, as
// it does for LayerMaterial.
//
// Tests: tests/reference_fem/test_viscoelastic_material.cpp.
#pragma once

#include <deal.II/base/symmetric_tensor.h>

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <puncture/fem/hyperelastic_materials.hpp>

namespace puncture::fem {

/// One term of the Prony series on the isochoric part.
struct PronyTerm {
  double beta;   ///< beta_i >= 0, dimensionless: free-energy factor relative to the long-term isochoric law
  double tau_s;  ///< tau_i > 0, s: relaxation time
};

/// One term of a normalised Prony series g(t) = 1 - sum_i g_i (1 - exp(-t/tau_i)).
struct NormalisedPronyTerm {
  double g;      ///< g_i >= 0, dimensionless: fraction of the instantaneous modulus that relaxes with tau_i
  double tau_s;  ///< tau_i > 0, s
};

/// Throws std::invalid_argument naming the first bad term ("Prony term 1: ...").
inline void check_prony_terms(const std::vector<PronyTerm>& terms) {
  for (std::size_t i = 0; i < terms.size(); ++i) {
    const PronyTerm& t = terms[i];
    if (!std::isfinite(t.beta) || !(t.beta >= 0.0))
      throw std::invalid_argument("Prony term " + std::to_string(i) + ": beta must be finite and >= 0 (got " +
                                  std::to_string(t.beta) + ")");
    if (!std::isfinite(t.tau_s) || !(t.tau_s > 0.0))
      throw std::invalid_argument("Prony term " + std::to_string(i) + ": tau must be finite and > 0 s (got " +
                                  std::to_string(t.tau_s) + ")");
  }
}

/// beta_i = g_i / g_inf, g_inf = 1 - sum g_i (must be > 0: something must be
/// left of the stress at equilibrium for a solid).
inline std::vector<PronyTerm> prony_terms_from_normalised(const std::vector<NormalisedPronyTerm>& normalised) {
  double g_inf = 1.0;
  for (std::size_t i = 0; i < normalised.size(); ++i) {
    const NormalisedPronyTerm& t = normalised[i];
    if (!std::isfinite(t.g) || !(t.g >= 0.0))
      throw std::invalid_argument("Prony term " + std::to_string(i) + ": g must be finite and >= 0 (got " +
                                  std::to_string(t.g) + ")");
    g_inf -= t.g;
  }
  if (!(g_inf > 0.0)) throw std::invalid_argument("Prony series: the g_i must sum to less than 1");
  std::vector<PronyTerm> terms;
  for (const NormalisedPronyTerm& t : normalised) terms.push_back({t.g / g_inf, t.tau_s});
  check_prony_terms(terms);
  return terms;
}

/// History of one quadrature point at the end of the last converged step t_n.
struct ViscoelasticHistory {
  std::vector<SymTensor2> Q_Pa;  ///< Q_i^n, non-equilibrium 2nd Piola-Kirchhoff stress of term i, Pa
  SymTensor2 S_iso_inf_Pa;       ///< S_iso^{inf,n}, long-term isochoric 2nd Piola-Kirchhoff stress, Pa
};

namespace detail {
// The long-term isochoric law: one of the classes of hyperelastic_materials.hpp
// (stress, stress_and_tangent) or a LayerMaterial (isochoric_*; it dispatches
// over its variant of those classes). Overload resolution picks the
// non-template LayerMaterial versions for a LayerMaterial.
template <class Law>
void long_term_isochoric(const Law& law, const SymTensor2& C, SymTensor2& S, SymTensor4& CC) {
  law.stress_and_tangent(C, S, CC);
}
inline void long_term_isochoric(const LayerMaterial& m, const SymTensor2& C, SymTensor2& S, SymTensor4& CC) {
  m.isochoric_stress_and_tangent(C, S, CC);
}
template <class Law>
SymTensor2 long_term_isochoric_stress(const Law& law, const SymTensor2& C) {
  return law.stress(C);
}
inline SymTensor2 long_term_isochoric_stress(const LayerMaterial& m, const SymTensor2& C) {
  return m.isochoric_stress(C);
}
}  // namespace detail

/// Simo/Holzapfel finite-strain viscoelastic material: an elastic long-term
/// law (IsochoricLaw + VolumetricLaw) with a Prony series on the isochoric
/// part. Stateless itself; the state is the caller's ViscoelasticHistory.
template <class IsochoricLaw>
class ViscoelasticMaterial {
 public:
  /// long_term_isochoric: the fully relaxed isochoric law; volumetric: the
  /// (elastic) bulk law; terms: the Prony series (may be empty: elastic).
  ViscoelasticMaterial(IsochoricLaw long_term_isochoric, VolumetricLaw volumetric, std::vector<PronyTerm> terms)
      : iso_(std::move(long_term_isochoric)), vol_(volumetric), terms_(std::move(terms)) {
    check_prony_terms(terms_);
  }

  const IsochoricLaw& long_term_isochoric() const { return iso_; }
  const VolumetricLaw& volumetric() const { return vol_; }
  const std::vector<PronyTerm>& prony_terms() const { return terms_; }

  /// The undisturbed past: Q_i = 0, S_iso^inf = 0 (the reference state is stress free).
  ViscoelasticHistory initial_history() const {
    return ViscoelasticHistory{std::vector<SymTensor2>(terms_.size()), SymTensor2()};
  }

  /// 1 + sum beta_i: instantaneous / long-term isochoric stiffness.
  double instantaneous_factor() const {
    double f = 1.0;
    for (const PronyTerm& t : terms_) f += t.beta;
    return f;
  }
  /// g(t) = (1 + sum beta_i exp(-t/tau_i)) / (1 + sum beta_i), t >= 0 in s:
  /// the isochoric stress after a sudden strain held for t, over its value at 0+.
  double relaxation_function(double t_s) const {
    if (!(t_s >= 0.0)) throw std::invalid_argument("relaxation_function: time must be >= 0 s");
    double g = 1.0;
    for (const PronyTerm& t : terms_) g += t.beta * std::exp(-t_s / t.tau_s);
    return g / instantaneous_factor();
  }
  /// g(inf) = 1 / (1 + sum beta_i): the fraction of the instantaneous
  /// isochoric stress left when everything has relaxed.
  double relaxed_fraction() const { return 1.0 / instantaneous_factor(); }
  /// 1 + delta = 1 + sum beta_i exp(-dt/(2 tau_i)): the factor on CC_iso^inf
  /// in the algorithmic tangent of a step dt (s).
  double tangent_factor(double dt_s) const {
    check_time_step(dt_s);
    double f = 1.0;
    for (const PronyTerm& t : terms_) f += t.beta * std::exp(-0.5 * dt_s / t.tau_s);
    return f;
  }

  /// Isochoric part at the end of a step of length dt_s from `history`:
  /// S = S_iso^inf(C) + sum_i Q_i^{n+1}(C),  CC = (1 + delta) CC_iso^inf(C).
  void isochoric_stress_and_tangent(const SymTensor2& C, double dt_s, const ViscoelasticHistory& history,
                                    SymTensor2& S, SymTensor4& CC) const {
    check_step(dt_s, history);
    SymTensor2 S_inf;
    SymTensor4 CC_inf;
    detail::long_term_isochoric(iso_, C, S_inf, CC_inf);
    S = S_inf;
    double delta = 0.0;
    for (std::size_t i = 0; i < terms_.size(); ++i) {
      S += non_equilibrium_stress(i, S_inf, dt_s, history);
      delta += terms_[i].beta * std::exp(-0.5 * dt_s / terms_[i].tau_s);
    }
    CC = (1.0 + delta) * CC_inf;
  }
  /// The isochoric S alone (residual-only evaluations).
  SymTensor2 isochoric_stress(const SymTensor2& C, double dt_s, const ViscoelasticHistory& history) const {
    check_step(dt_s, history);
    const SymTensor2 S_inf = detail::long_term_isochoric_stress(iso_, C);
    SymTensor2 S = S_inf;
    for (std::size_t i = 0; i < terms_.size(); ++i) S += non_equilibrium_stress(i, S_inf, dt_s, history);
    return S;
  }

  /// Total stress and tangent with the volumetric law at the pointwise J
  /// (one-field): S = S_vol + S_iso^inf + sum_i Q_i,
  /// CC = CC_vol + (1 + delta) CC_iso^inf, CC_vol = p J (C^-1 x C^-1
  /// - 2 C^-1 (.) C^-1) + J^2 dp/dJ C^-1 x C^-1, p = dPsi_vol/dJ.
  void stress_and_tangent(const SymTensor2& C, double dt_s, const ViscoelasticHistory& history, SymTensor2& S,
                          SymTensor4& CC) const {
    isochoric_stress_and_tangent(C, dt_s, history, S, CC);
    const double J = std::sqrt(dealii::determinant(C));
    const SymTensor2 C_inv = dealii::invert(C);
    add_volumetric_at_fixed_pressure(C_inv, J, vol_.pressure(J), S, CC);
    CC += (J * J * vol_.dpressure_dJ(J)) * outer(C_inv, C_inv);
  }
  SymTensor2 stress(const SymTensor2& C, double dt_s, const ViscoelasticHistory& history) const {
    SymTensor2 S = isochoric_stress(C, dt_s, history);
    const double J = std::sqrt(dealii::determinant(C));
    S += (vol_.pressure(J) * J) * dealii::invert(C);
    return S;
  }

  /// End of a converged step of length dt_s at C: Q_i^n <- Q_i^{n+1},
  /// S_iso^{inf,n} <- S_iso^inf(C). Call once per step.
  void commit(const SymTensor2& C, double dt_s, ViscoelasticHistory& history) const {
    check_step(dt_s, history);
    const SymTensor2 S_inf = detail::long_term_isochoric_stress(iso_, C);
    for (std::size_t i = 0; i < terms_.size(); ++i)
      history.Q_Pa[i] = non_equilibrium_stress(i, S_inf, dt_s, history);
    history.S_iso_inf_Pa = S_inf;
  }

 private:
  /// Q_i^{n+1} = H_i + beta_i exp(xi_i) S_iso^{inf,n+1},
  /// H_i = exp(xi_i) (exp(xi_i) Q_i^n - beta_i S_iso^{inf,n}), xi_i = -dt/(2 tau_i).
  SymTensor2 non_equilibrium_stress(std::size_t i, const SymTensor2& S_inf_new, double dt_s,
                                    const ViscoelasticHistory& history) const {
    const double beta = terms_[i].beta;
    const double e = std::exp(-0.5 * dt_s / terms_[i].tau_s);  // exp(xi_i)
    const SymTensor2 H = e * (e * history.Q_Pa[i] - beta * history.S_iso_inf_Pa);
    return H + (beta * e) * S_inf_new;
  }
  static void check_time_step(double dt_s) {
    if (!std::isfinite(dt_s) || !(dt_s >= 0.0))
      throw std::invalid_argument("viscoelastic material: time step must be finite and >= 0 s");
  }
  void check_step(double dt_s, const ViscoelasticHistory& history) const {
    check_time_step(dt_s);
    if (history.Q_Pa.size() != terms_.size())
      throw std::invalid_argument("viscoelastic material: history has " + std::to_string(history.Q_Pa.size()) +
                                  " Prony stresses, the material " + std::to_string(terms_.size()) + " terms");
  }

  IsochoricLaw iso_;              ///< long-term (relaxed) isochoric law
  VolumetricLaw vol_;             ///< elastic bulk law
  std::vector<PronyTerm> terms_;  ///< Prony series on the isochoric part
};

/// A layer of the scene made viscoelastic: its LayerMaterial (isochoric law of
/// the scene's model, volumetric law from E and nu) as the long-term response.
inline ViscoelasticMaterial<LayerMaterial> make_viscoelastic_layer(const LayerMaterial& long_term,
                                                                   std::vector<PronyTerm> terms) {
  return ViscoelasticMaterial<LayerMaterial>(long_term, long_term.volumetric(), std::move(terms));
}

}  // namespace puncture::fem
