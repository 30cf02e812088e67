// ForceMesh with stiffening in the mesh (force_mesh.hpp, "Stiffening in the
// mesh"): the springs' laws, the step's Newton solve on the fixed-pattern
// tangent, and the linearised prediction the layer chain uses.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "fixed_pattern_ldlt.hpp"
#include "puncture/force_mesh.hpp"

namespace puncture {

namespace detail {

TangentFactorization::TangentFactorization() = default;
TangentFactorization::~TangentFactorization() = default;
TangentFactorization::TangentFactorization(TangentFactorization&&) noexcept = default;
TangentFactorization& TangentFactorization::operator=(TangentFactorization&&) noexcept = default;
TangentFactorization::TangentFactorization(const TangentFactorization& other)
    : ldlt_(other.ldlt_ ? std::make_unique<FixedPatternLdlt>(*other.ldlt_) : nullptr) {}
TangentFactorization& TangentFactorization::operator=(const TangentFactorization& other) {
  if (this != &other) ldlt_ = other.ldlt_ ? std::make_unique<FixedPatternLdlt>(*other.ldlt_) : nullptr;
  return *this;
}
void TangentFactorization::create() { ldlt_ = std::make_unique<FixedPatternLdlt>(); }

}  // namespace detail

double virtual_spring_force_N(const ForceMeshParams& p, double z) {
  const double K = p.virtual_stiffness_N_per_m;
  if (!(p.virtual_stiffening_m > 0.0)) return K * z;
  const double x = z / p.virtual_stiffening_m;
  return K * z * (1.0 + x * x);
}

double virtual_spring_stiffness_N_per_m(const ForceMeshParams& p, double z) {
  const double K = p.virtual_stiffness_N_per_m;
  if (!(p.virtual_stiffening_m > 0.0)) return K;
  const double x = z / p.virtual_stiffening_m;
  return K * (1.0 + 3.0 * x * x);
}

double virtual_spring_energy_J(const ForceMeshParams& p, double z) {
  const double K = p.virtual_stiffness_N_per_m;
  if (!(p.virtual_stiffening_m > 0.0)) return 0.5 * K * z * z;
  const double x = z / p.virtual_stiffening_m;
  return K * z * z * (0.5 + 0.25 * x * x);
}

namespace {

/// One surface spring's transverse force and stiffness in one pass (the law
/// of surface_spring_force_N and surface_spring_stiffness_N_per_m, which call
/// it; the step's loops use it directly). (s - L) / s = delta^2 / (s (s + L))
/// and 1 - L^3 / s^3 = delta^2 (s^2 + s L + L^2) / ((s + L) s^3): no
/// cancellation at small slopes.
struct SurfaceSpringLaw {
  double ks, ka, L;
  void evaluate(double delta, double& force, double& stiffness) const {
    force = ks * delta;
    stiffness = ks;
    if (ka > 0.0) {
      const double s = std::sqrt(L * L + delta * delta);
      const double d2 = delta * delta;
      force += ka * d2 * delta / (s * (s + L));
      stiffness += ka * d2 * (s * s + s * L + L * L) / ((s + L) * s * s * s);
    }
  }
};

}  // namespace

double surface_spring_force_N(const ForceMeshParams& p, double delta) {
  double f = 0.0, k = 0.0;
  SurfaceSpringLaw{p.surface_stiffness_N_per_m, p.surface_axial_stiffness_N_per_m, p.spacing_L_m}.evaluate(delta, f, k);
  return f;
}

double surface_spring_stiffness_N_per_m(const ForceMeshParams& p, double delta) {
  double f = 0.0, k = 0.0;
  SurfaceSpringLaw{p.surface_stiffness_N_per_m, p.surface_axial_stiffness_N_per_m, p.spacing_L_m}.evaluate(delta, f, k);
  return k;
}

double surface_spring_energy_J(const ForceMeshParams& p, double delta) {
  double e = 0.5 * p.surface_stiffness_N_per_m * delta * delta;
  if (p.surface_axial_stiffness_N_per_m > 0.0) {
    const double L = p.spacing_L_m;
    const double stretch = delta * delta / (std::hypot(L, delta) + L);  // s - L
    e += 0.5 * p.surface_axial_stiffness_N_per_m * stretch * stretch;
  }
  return e;
}

void ForceMesh::setup_nonlinear() {
  const int n = lattice_.node_count();
  const int nf = n - 1;
  const double dt = settings_.time_step_s;
  step_mass_term_ = use_implicit_ ? mass_kg_ / (dt * dt) + params_.node_damping_N_s_per_m / dt : 0.0;
  spring_i_.clear();
  spring_j_.clear();
  std::vector<std::pair<int, int>> lower;  // free-node indices f = node - 1
  for (int f = 0; f < nf; ++f) lower.push_back({f, f});
  for (int i = 1; i < n; ++i)
    for (int k = lattice_.neighbour_offsets[i]; k < lattice_.neighbour_offsets[i + 1]; ++k) {
      const int j = lattice_.neighbours[k];
      if (j > i) {
        spring_i_.push_back(i);
        spring_j_.push_back(j);
        lower.push_back({j - 1, i - 1});
      }
    }
  qz_.setZero(n);
  qv_.setZero(n);
  inertial_target_.setZero(std::max(nf, 1));
  trial_z_.setZero(n);
  newton_step_.setZero(std::max(nf, 1));
  tangent_values_.assign(lower.size(), 0.0);
  if (nf > 0) {
    tangent_.create();
    tangent_->analyse(nf, lower);
  }
  reaction_slope_N_per_m_ = static_stiffness_N_per_m_;
}


double ForceMesh::nonlinear_residual(double z0) {
  // Node terms, then every spring once (free-free springs, then those to the contact node).
  const int n = lattice_.node_count();
  const SurfaceSpringLaw law{params_.surface_stiffness_N_per_m, params_.surface_axial_stiffness_N_per_m,
                             params_.spacing_L_m};
  pz_[0] = z0;
  for (int i = 1; i < n; ++i)
    rhs_[i - 1] = step_mass_term_ * (pz_[i] - inertial_target_[i - 1]) + virtual_spring_force_N(params_, pz_[i]);
  double f = 0.0, k = 0.0;
  for (std::size_t e = 0; e < spring_i_.size(); ++e) {
    const int i = spring_i_[e], j = spring_j_[e];
    law.evaluate(pz_[i] - pz_[j], f, k);
    rhs_[i - 1] += f;
    rhs_[j - 1] -= f;
  }
  for (int q = lattice_.neighbour_offsets[0]; q < lattice_.neighbour_offsets[1]; ++q) {
    const int i = lattice_.neighbours[q];
    law.evaluate(pz_[i] - z0, f, k);
    rhs_[i - 1] += f;
  }
  return n > 1 ? rhs_.cwiseAbs().maxCoeff() : 0.0;
}

void ForceMesh::factorize_tangent(double z0) {
  const int n = lattice_.node_count();
  const SurfaceSpringLaw law{params_.surface_stiffness_N_per_m, params_.surface_axial_stiffness_N_per_m,
                             params_.spacing_L_m};
  pz_[0] = z0;
  for (int i = 1; i < n; ++i) tangent_values_[i - 1] = step_mass_term_ + virtual_spring_stiffness_N_per_m(params_, pz_[i]);
  const std::size_t diagonal = static_cast<std::size_t>(n - 1);
  double f = 0.0, k = 0.0;
  for (std::size_t e = 0; e < spring_i_.size(); ++e) {
    const int i = spring_i_[e], j = spring_j_[e];
    law.evaluate(pz_[i] - pz_[j], f, k);
    tangent_values_[i - 1] += k;
    tangent_values_[j - 1] += k;
    tangent_values_[diagonal + e] = -k;
  }
  for (int q = lattice_.neighbour_offsets[0]; q < lattice_.neighbour_offsets[1]; ++q) {
    const int i = lattice_.neighbours[q];
    law.evaluate(pz_[i] - z0, f, k);
    tangent_values_[i - 1] += k;
  }
  if (!tangent_->factorize(tangent_values_.data()))
    throw std::runtime_error("force mesh: the stiffening mesh's tangent is not positive definite (non-finite deflections?)");
  tangent_ready_ = true;
}

void ForceMesh::solve_nonlinear_step(double z0) {
  const int n = lattice_.node_count();
  const int nf = n - 1;
  const double dt = settings_.time_step_s;
  pz_ = z_;
  pz_[0] = z0;
  newton_iterations_ = 0;
  if (nf == 0) {
    pv_.setZero();
    return;
  }
  if (use_implicit_) {
    const double m_dt2 = mass_kg_ / (dt * dt), c_dt = params_.node_damping_N_s_per_m / dt;
    for (int i = 1; i < n; ++i)
      inertial_target_[i - 1] = (m_dt2 * (z_[i] + dt * v_[i]) + c_dt * z_[i]) / step_mass_term_;
  }
  // Newton on the step equations; the energy is strictly convex, so a
  // backtracking line search on the residual's max norm keeps every step.
  // Converged when the full Newton step is below 1e-12 of the deflections or
  // the residual below 1e-10 of the springs' force at that deflection (their
  // tangent stiffness there times the deflection).
  double scale = std::max(std::abs(z0), params_.deformed_threshold_m);
  for (int i = 1; i < n; ++i) scale = std::max(scale, std::abs(z_[i]));
  const double tolerance_m = 1e-12 * scale;
  const double force_floor_N = 1e-10 * scale *
                               (virtual_spring_stiffness_N_per_m(params_, scale) +
                                surface_spring_stiffness_N_per_m(params_, scale) + step_mass_term_);
  constexpr int kMaxNewton = 40;
  constexpr int kMaxCuts = 40;
  double residual = nonlinear_residual(z0);
  double last_step = 0.0;  // full Newton step of the last iteration (m)
  while (residual > force_floor_N) {
    if (newton_iterations_ >= kMaxNewton)
      throw std::runtime_error("force mesh: the stiffening mesh's step did not converge in " +
                               std::to_string(kMaxNewton) + " Newton iterations (contact deflection " +
                               std::to_string(z0 * 1e3) + " mm)");
    factorize_tangent(z0);
    rhs_ = -rhs_;
    tangent_->solve(rhs_, newton_step_);
    ++newton_iterations_;
    const double step_size = newton_step_.cwiseAbs().maxCoeff();
    if (!std::isfinite(step_size)) throw std::runtime_error("force mesh: non-finite Newton step in the stiffening mesh");
    trial_z_ = pz_;
    double alpha = 1.0;
    for (int cut = 0;; ++cut) {
      for (int f = 0; f < nf; ++f) pz_[f + 1] = trial_z_[f + 1] + alpha * newton_step_[f];
      const double r = nonlinear_residual(z0);
      if (r <= residual || r <= force_floor_N) {
        residual = r;
        break;
      }
      if (cut == kMaxCuts)
        throw std::runtime_error("force mesh: no Newton step of the stiffening mesh lowers its residual (contact "
                                 "deflection " + std::to_string(z0 * 1e3) + " mm)");
      alpha *= 0.5;
    }
    last_step = step_size;
    if (step_size <= tolerance_m) break;
  }
  // pz_ converged (rhs_ holds its residual); the tangent there gives the
  // sensitivity dz/dz0. The last factorisation is at most one tiny Newton
  // step (<= 1e-3 of the deflections) away: it is kept then; the predicted
  // slope is then off by about that fraction of the tangent's change over the
  // step (a tick of needle travel), and the next predict() solves the true step.
  if (!tangent_ready_ || last_step > 1e-3 * scale) factorize_tangent(z0);
  rhs_.setZero();
  for (int k = lattice_.neighbour_offsets[0]; k < lattice_.neighbour_offsets[1]; ++k) {
    const int j = lattice_.neighbours[k];
    rhs_[j - 1] = surface_spring_stiffness_N_per_m(params_, pz_[j] - z0);
  }
  tangent_->solve(rhs_, newton_step_);
  qz_[0] = 1.0;
  qv_[0] = 0.0;
  for (int i = 1; i < n; ++i) {
    qz_[i] = newton_step_[i - 1];
    qv_[i] = use_implicit_ ? qz_[i] / dt : 0.0;
    pv_[i] = use_implicit_ ? (pz_[i] - z_[i]) / dt : 0.0;
  }
}

void ForceMesh::predict_nonlinear(double z0_star) {
  // The step solved at contact deflection z0_star, linearised there (see the header).
  predicted_z0_ = z0_star;
  solve_nonlinear_step(predicted_z0_);
  double reaction = virtual_spring_force_N(params_, predicted_z0_);
  double slope = virtual_spring_stiffness_N_per_m(params_, predicted_z0_);
  for (int k = lattice_.neighbour_offsets[0]; k < lattice_.neighbour_offsets[1]; ++k) {
    const int j = lattice_.neighbours[k];
    reaction += surface_spring_force_N(params_, predicted_z0_ - pz_[j]);
    slope += surface_spring_stiffness_N_per_m(params_, predicted_z0_ - pz_[j]) * (1.0 - qz_[j]);
  }
  reaction_slope_N_per_m_ = slope;
  predicted_intercept_N_ = reaction - slope * predicted_z0_;
  predicted_ = true;
}

}  // namespace puncture
