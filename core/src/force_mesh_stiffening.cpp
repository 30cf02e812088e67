// ForceMesh with stiffening in the mesh (force_mesh.hpp, "Stiffening in the
// mesh"): the springs' laws, the step's Newton solve on the fixed-pattern
// tangent, and the linearised prediction the layer chain uses.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "fixed_pattern_ldlt.hpp"
#include "lattice_cells.hpp"
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

void ForceMesh::setup_cells() {
  // The lattice's cells (lattice_cells.hpp) and the pairs of adjacent cells.
  const detail::LatticeCells cells = detail::equitable_cells(lattice_);
  const int nc = cells.count();
  cell_of_ = cells.cell_of;
  cell_rep_ = cells.representative;
  cell_size_.resize(nc);
  for (int a = 0; a < nc; ++a) cell_size_[a] = cells.size[a];
  pairs_.clear();
  contact_pairs_.clear();
  for (const detail::LatticeCells::Pair& p : cells.pairs) {
    const CellPair pair{p.a, p.b, static_cast<double>(p.edges), p.edges / cell_size_[p.a], p.edges / cell_size_[p.b]};
    (p.a == 0 ? contact_pairs_ : pairs_).push_back(pair);
  }
}

void ForceMesh::setup_nonlinear() {
  // The step is solved on the lattice's cells: one unknown per free cell
  // a = cell - 1, the tangent weighted by the cells' sizes (symmetric:
  // |A| n_AB = |B| n_BA springs between A and B).
  const double dt = settings_.time_step_s;
  step_mass_term_ = use_implicit_ ? mass_kg_ / (dt * dt) + params_.node_damping_N_s_per_m / dt : 0.0;
  const int nc = static_cast<int>(cell_size_.size());
  const int mf = nc - 1;
  std::vector<std::pair<int, int>> lower;  // free-cell indices a = cell - 1
  for (int a = 0; a < mf; ++a) lower.push_back({a, a});
  for (const CellPair& p : pairs_) lower.push_back({p.b - 1, p.a - 1});
  cell_state_z_.setZero(nc);
  cell_state_v_.setZero(nc);
  cell_pz_.setZero(nc);
  cell_pv_.setZero(nc);
  cell_qz_.setZero(nc);
  cell_qv_.setZero(nc);
  pair_stiffness_.assign(pairs_.size(), 0.0);
  contact_pair_stiffness_.assign(contact_pairs_.size(), 0.0);
  cell_virtual_stiffness_.assign(nc, 0.0);
  cell_z_.setZero(nc);
  trial_cell_z_.setZero(nc);
  const int m = std::max(mf, 1);
  inertial_target_.setZero(m);
  cell_residual_.setZero(m);
  newton_step_.setZero(m);
  tangent_values_.assign(lower.size(), 0.0);
  if (mf > 0) {
    tangent_.create();
    tangent_->analyse(mf, lower);
  }
  reaction_slope_N_per_m_ = static_stiffness_N_per_m_;
}

double ForceMesh::nonlinear_residual(double z0) {
  // Every free node's residual, one per cell (cell_z_[0] = z0): node terms,
  // then the springs between cells, each pair once. The springs' tangent at
  // this state is kept for factorize_tangent.
  const int nc = static_cast<int>(cell_size_.size());
  const SurfaceSpringLaw law{params_.surface_stiffness_N_per_m, params_.surface_axial_stiffness_N_per_m,
                             params_.spacing_L_m};
  cell_z_[0] = z0;
  for (int a = 1; a < nc; ++a) {
    cell_residual_[a - 1] =
        step_mass_term_ * (cell_z_[a] - inertial_target_[a - 1]) + virtual_spring_force_N(params_, cell_z_[a]);
    cell_virtual_stiffness_[a] = virtual_spring_stiffness_N_per_m(params_, cell_z_[a]);
  }
  double f = 0.0;
  for (std::size_t e = 0; e < pairs_.size(); ++e) {
    const CellPair& p = pairs_[e];
    law.evaluate(cell_z_[p.a] - cell_z_[p.b], f, pair_stiffness_[e]);
    cell_residual_[p.a - 1] += p.per_node_a * f;
    cell_residual_[p.b - 1] -= p.per_node_b * f;
  }
  for (std::size_t e = 0; e < contact_pairs_.size(); ++e) {
    const CellPair& p = contact_pairs_[e];
    law.evaluate(cell_z_[p.b] - z0, f, contact_pair_stiffness_[e]);
    cell_residual_[p.b - 1] += p.per_node_b * f;
  }
  return nc > 1 ? cell_residual_.cwiseAbs().maxCoeff() : 0.0;
}

void ForceMesh::factorize_tangent() {
  // The tangent of the cells' residuals, each row times the cell's size, from
  // the springs' tangent the last nonlinear_residual() kept (at cell_z_).
  const int nc = static_cast<int>(cell_size_.size());
  for (int a = 1; a < nc; ++a) tangent_values_[a - 1] = cell_size_[a] * (step_mass_term_ + cell_virtual_stiffness_[a]);
  const std::size_t diagonal = static_cast<std::size_t>(nc - 1);
  for (std::size_t e = 0; e < pairs_.size(); ++e) {
    const CellPair& p = pairs_[e];
    const double k = pair_stiffness_[e];
    tangent_values_[p.a - 1] += p.edges * k;
    tangent_values_[p.b - 1] += p.edges * k;
    tangent_values_[diagonal + e] = -p.edges * k;
  }
  for (std::size_t e = 0; e < contact_pairs_.size(); ++e)
    tangent_values_[contact_pairs_[e].b - 1] += contact_pairs_[e].edges * contact_pair_stiffness_[e];
  if (!tangent_->factorize(tangent_values_.data()))
    throw std::runtime_error("force mesh: the stiffening mesh's tangent is not positive definite (non-finite deflections?)");
  tangent_ready_ = true;
}

double ForceMesh::newton_solve_cells(double z0, double scale) {
  // Newton on the step equations; the energy is strictly convex, so a
  // backtracking line search on the residual's max norm keeps every step.
  // Converged when the full Newton step is below 1e-12 of the deflections or
  // the residual below 1e-10 of the springs' force at that deflection (their
  // tangent stiffness there times the deflection). Returns the last full step (m).
  const int mf = static_cast<int>(cell_size_.size()) - 1;
  const double tolerance_m = 1e-12 * scale;
  const double force_floor_N = 1e-10 * scale *
                               (virtual_spring_stiffness_N_per_m(params_, scale) +
                                surface_spring_stiffness_N_per_m(params_, scale) + step_mass_term_);
  constexpr int kMaxNewton = 40;
  constexpr int kMaxCuts = 40;
  double residual = nonlinear_residual(z0);
  double last_step = 0.0;
  while (residual > force_floor_N) {
    if (newton_iterations_ >= kMaxNewton)
      throw std::runtime_error("force mesh: the stiffening mesh's step did not converge in " +
                               std::to_string(kMaxNewton) + " Newton iterations (contact deflection " +
                               std::to_string(z0 * 1e3) + " mm)");
    factorize_tangent();
    for (int a = 0; a < mf; ++a) cell_residual_[a] *= -cell_size_[a + 1];
    tangent_->solve(cell_residual_, newton_step_);
    ++newton_iterations_;
    const double step_size = newton_step_.cwiseAbs().maxCoeff();
    if (!std::isfinite(step_size)) throw std::runtime_error("force mesh: non-finite Newton step in the stiffening mesh");
    trial_cell_z_ = cell_z_;
    double alpha = 1.0;
    for (int cut = 0;; ++cut) {
      for (int a = 0; a < mf; ++a) cell_z_[a + 1] = trial_cell_z_[a + 1] + alpha * newton_step_[a];
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
  return last_step;
}

void ForceMesh::solve_nonlinear_step(double z0) {
  const int nc = static_cast<int>(cell_size_.size());
  const double dt = settings_.time_step_s;
  newton_iterations_ = 0;
  cell_pz_[0] = z0;
  cell_pv_[0] = 0.0;
  cell_qz_[0] = 1.0;
  cell_qv_[0] = 0.0;
  if (nc == 1) return;
  // The committed state is constant on the cells (cell_state_z_, cell_state_v_).
  double scale = std::max(std::abs(z0), params_.deformed_threshold_m);
  for (int a = 1; a < nc; ++a) {
    const double z = cell_state_z_[a];
    cell_z_[a] = z;
    scale = std::max(scale, std::abs(z));
    if (use_implicit_) {
      const double m_dt2 = mass_kg_ / (dt * dt), c_dt = params_.node_damping_N_s_per_m / dt;
      inertial_target_[a - 1] = (m_dt2 * (z + dt * cell_state_v_[a]) + c_dt * z) / step_mass_term_;
    }
  }
  const double last_step = newton_solve_cells(z0, scale);
  // cell_z_ converged; the tangent there gives the sensitivity dz/dz0. The
  // last factorisation is at most one tiny Newton step (<= 1e-3 of the
  // deflections) away: it is kept then; the predicted slope is then off by
  // about that fraction of the tangent's change over the step (a tick of
  // needle travel), and the next predict() solves the true step.
  if (!tangent_ready_ || last_step > 1e-3 * scale) factorize_tangent();
  cell_residual_.setZero();
  for (std::size_t e = 0; e < contact_pairs_.size(); ++e)
    cell_residual_[contact_pairs_[e].b - 1] = contact_pairs_[e].edges * contact_pair_stiffness_[e];
  tangent_->solve(cell_residual_, newton_step_);
  for (int a = 1; a < nc; ++a) {
    cell_pz_[a] = cell_z_[a];
    cell_qz_[a] = newton_step_[a - 1];
    cell_qv_[a] = use_implicit_ ? cell_qz_[a] / dt : 0.0;
    cell_pv_[a] = use_implicit_ ? (cell_pz_[a] - cell_state_z_[a]) / dt : 0.0;
  }
}

void ForceMesh::predict_nonlinear(double z0_star) {
  // The step solved at contact deflection z0_star, linearised there (see the header).
  predicted_z0_ = z0_star;
  solve_nonlinear_step(predicted_z0_);
  double reaction = virtual_spring_force_N(params_, predicted_z0_);
  double slope = virtual_spring_stiffness_N_per_m(params_, predicted_z0_);
  for (int k = lattice_.neighbour_offsets[0]; k < lattice_.neighbour_offsets[1]; ++k) {
    const int c = cell_of_[lattice_.neighbours[k]];
    reaction += surface_spring_force_N(params_, predicted_z0_ - cell_pz_[c]);
    slope += surface_spring_stiffness_N_per_m(params_, predicted_z0_ - cell_pz_[c]) * (1.0 - cell_qz_[c]);
  }
  reaction_slope_N_per_m_ = slope;
  predicted_intercept_N_ = reaction - slope * predicted_z0_;
  predicted_ = true;
}

}  // namespace puncture
