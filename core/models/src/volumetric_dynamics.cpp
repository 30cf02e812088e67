// volumetric_dynamics.cpp: the equations of motion of VolumetricNeedleModel
// (lumped masses, internal forces with stiffness damping) and what SUNDIALS
// asks of them (right-hand side, preconditioner setup and solve, Jacobian
// times vector); see volumetric_model.hpp.
#include "puncture/comparison/volumetric_model.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

namespace puncture::comparison {

void VolumetricNeedleModel::compute_masses() {
  std::vector<double> node_mass(static_cast<std::size_t>(nodes_), 0.0);
  for (std::size_t t = 0; t < mesh_->tets.size(); ++t) {
    if (removed_[t]) continue;
    const Eigen::Vector4i& v = mesh_->tets[t];
    const double volume = meshing::tet_signed_volume(mesh_->points_m.col(v[0]), mesh_->points_m.col(v[1]),
                                            mesh_->points_m.col(v[2]), mesh_->points_m.col(v[3]));
    const double m = scene_->layers[static_cast<std::size_t>(mesh_->layer[t])].density_kg_per_m3 * volume / 4.0;
    for (int i = 0; i < 4; ++i) node_mass[static_cast<std::size_t>(v[i])] += m;
  }
  mass_.resize(3 * nodes_);
  for (int a = 0; a < nodes_; ++a) {
    mass_.segment<3>(3 * a).setConstant(node_mass[static_cast<std::size_t>(a)]);
    if (!(node_mass[static_cast<std::size_t>(a)] > 0.0)) dof_[static_cast<std::size_t>(a)] = Dof::Fixed;  // orphan
  }
}

void VolumetricNeedleModel::drop_factors() {
  factors_.clear();
  factor_in_use_ = nullptr;
}

void VolumetricNeedleModel::compute_rest_tangent() {
  if (rest_tangent_.node_count() == 0) return;  // not needed (constructor)
  rest_tangent_.set_zero();
  law_->add_tangent(rest_, 0.0, rest_tangent_);
}

void VolumetricNeedleModel::compute_forces(const Eigen::VectorXd& y, Eigen::VectorXd& f) const {
  f.setZero(3 * nodes_);
  std::vector<double> qdot(static_cast<std::size_t>(extra_));
  law_->add_forces(y.head(3 * nodes_), y.segment(3 * nodes_, 3 * nodes_), y.data() + 6 * nodes_, f,
                   extra_ ? qdot.data() : nullptr);
  if (settings_.stiffness_damping_s > 0.0)
    f.noalias() -= settings_.stiffness_damping_s * (rest_tangent_.matrix() * y.segment(3 * nodes_, 3 * nodes_));
}

int VolumetricNeedleModel::rhs(double, const double* yp, double* ydot) {
  const Eigen::Map<const Eigen::VectorXd> y(yp, y_.size());
  Eigen::Map<Eigen::VectorXd> out(ydot, y_.size());
  work_f_.setZero();
  law_->add_forces(y.head(3 * nodes_), y.segment(3 * nodes_, 3 * nodes_), yp + 6 * nodes_, work_f_,
                   extra_ ? ydot + 6 * nodes_ : nullptr);
  if (settings_.stiffness_damping_s > 0.0)
    work_f_.noalias() -= settings_.stiffness_damping_s * (rest_tangent_.matrix() * y.segment(3 * nodes_, 3 * nodes_));
  out.head(3 * nodes_) = y.segment(3 * nodes_, 3 * nodes_);
  const double alpha = settings_.mass_damping_per_s;
  for (int a = 0; a < nodes_; ++a) {
    const bool free = dof_[static_cast<std::size_t>(a)] == Dof::Free;
    for (int i = 0; i < 3; ++i) {
      const int d = 3 * a + i;
      out[3 * nodes_ + d] = free ? work_f_[d] / mass_[d] - alpha * y[3 * nodes_ + d] : 0.0;
    }
  }
  return 0;
}

bool VolumetricNeedleModel::has_preconditioner() const { return settings_.integrator == IntegratorKind::ImplicitBdf; }

bool VolumetricNeedleModel::has_jacobian_times() const {
  return settings_.integrator == IntegratorKind::ImplicitBdf && law_->tangent_is_exact() && extra_ == 0;
}

int VolumetricNeedleModel::preconditioner_setup(double, const double* yp, bool jok, bool& updated, double gamma) {
  const Eigen::Map<const Eigen::VectorXd> y(yp, y_.size());
  updated = false;
  if (!jok || !have_tangent_) {
    tangent_.set_zero();
    law_->add_tangent(y.head(3 * nodes_), gamma, tangent_);
    const Eigen::SparseMatrix<double>& K = tangent_.matrix();
    if (!Eigen::Map<const Eigen::VectorXd>(K.valuePtr(), K.nonZeros()).allFinite()) return 1;
    // Gershgorin bound on the largest eigenvalue of M^-1 K over the free dofs.
    omega_squared_bound_ = 0.0;
    for (Eigen::Index j = 0; j < K.outerSize(); ++j) {
      if (dof_[static_cast<std::size_t>(j / 3)] != Dof::Free) continue;
      double row = 0.0;  // K is symmetric: the column sum is the row sum
      for (Eigen::SparseMatrix<double>::InnerIterator it(K, j); it; ++it) row += std::abs(it.value());
      omega_squared_bound_ = std::max(omega_squared_bound_, row / mass_[j]);
    }
    have_tangent_ = true;
    // Lagged preconditioner: CVODE asks for fresh Jacobian data after every
    // restart (each contact change) and every 50 steps; the factorisation made
    // with an older tangent or contact set stays a good preconditioner (GMRES
    // absorbs the difference), so it is kept until a Newton iteration fails
    // to converge with it. Factorisations dominate the cost of a step.
    if (!settings_.lag_preconditioner || !integrator_ ||
        integrator_->stats().convergence_failures != factor_convergence_failures_)
      drop_factors();
    updated = true;
  }
  const double alpha = settings_.mass_damping_per_s, beta = settings_.stiffness_damping_s;
  // Small steps: gamma^2 K (and gamma beta K0) are small beside M, the diagonal
  // is a good enough preconditioner.
  mass_only_ = (gamma * gamma + gamma * beta) * omega_squared_bound_ < 0.25;
  if (mass_only_) {
    diagonal_.resize(3 * nodes_);
    const Eigen::SparseMatrix<double>& K = tangent_.matrix();
    for (int d = 0; d < 3 * nodes_; ++d)
      diagonal_[d] = dof_[static_cast<std::size_t>(d / 3)] == Dof::Free
                         ? (1.0 + gamma * alpha) * mass_[d] + gamma * gamma * K.coeff(d, d) +
                               (beta > 0.0 ? gamma * beta * rest_tangent_.matrix().coeff(d, d) : 0.0)
                         : 1.0;
    ++mass_only_setups_;
    return 0;
  }
  // A kept factorisation made with a gamma within kFactorReuse of this one
  // (the preconditioned spectrum stays within [1/f^2, f^2] and GMRES absorbs
  // the difference); the pool keeps several, as gamma ramps up after every
  // restart through the values of the last ramp.
  if (const SparseSpdFactor* kept = factors_.find(gamma)) {
    factor_in_use_ = kept;
    return 0;
  }
  const auto start = std::chrono::steady_clock::now();
  system_ = tangent_.matrix() * (gamma * gamma);
  if (beta > 0.0) system_ += rest_tangent_.matrix() * (gamma * beta);  // same pattern
  for (int d = 0; d < 3 * nodes_; ++d) system_.coeffRef(d, d) += (1.0 + gamma * alpha) * mass_[d];
  for (Eigen::Index j = 0; j < system_.outerSize(); ++j) {
    const bool col_free = dof_[static_cast<std::size_t>(j / 3)] == Dof::Free;
    for (Eigen::SparseMatrix<double>::InnerIterator it(system_, j); it; ++it) {
      const bool row_free = dof_[static_cast<std::size_t>(it.row() / 3)] == Dof::Free;
      if (row_free && col_free) continue;
      it.valueRef() = it.row() == it.col() ? 1.0 : 0.0;
    }
  }
  factor_in_use_ = factors_.factorize(gamma, system_);
  factorisation_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ++factorisations_;
  if (!factor_in_use_) return 1;
  factor_convergence_failures_ = integrator_ ? integrator_->stats().convergence_failures : 0;
  return 0;
}

int VolumetricNeedleModel::preconditioner_solve(double, const double* yp, const double* rp, double* zp, double gamma) {
  yp_current_ = yp;
  const int n3 = 3 * nodes_;
  const Eigen::Map<const Eigen::VectorXd> r(rp, y_.size());
  Eigen::Map<Eigen::VectorXd> z(zp, y_.size());
  const auto rx = r.head(n3);
  const auto rv = r.segment(n3, n3);
  const Eigen::SparseMatrix<double>& K = tangent_.matrix();
  Eigen::VectorXd b;
  // Internal variables (visco-elastic law): their residual enters the velocity
  // equation through their forces, eliminated exactly.
  Eigen::VectorXd q_force;
  if (extra_ > 0) {
    q_force = Eigen::VectorXd::Zero(n3);
    law_->add_internal_variable_forces(Eigen::Map<const Eigen::VectorXd>(yp_current_, n3), rp + 6 * nodes_, gamma, q_force);
  }
  if (mass_only_) {
    work_a_ = mass_.cwiseProduct(rv) - gamma * (K * rx);
    if (extra_ > 0) work_a_ += gamma * q_force;
    b = work_a_.cwiseQuotient(diagonal_);
  } else {
    // The prescribed dofs' values enter the free rows through the Newton
    // matrix of this gamma (the factorisation may have been made with another):
    // their columns of it only (a few hundred of the mesh's dofs, where a
    // product with a vector zero elsewhere swept every column).
    work_a_ = mass_.cwiseProduct(rv) - gamma * (K * rx);
    const Eigen::SparseMatrix<double>& K0 = rest_tangent_.matrix();
    const double damping = gamma * settings_.stiffness_damping_s;
    for (int d = 0; d < n3; ++d) {
      if (dof_[static_cast<std::size_t>(d / 3)] == Dof::Free || rv[d] == 0.0) continue;
      const double v = rv[d];
      work_a_[d] -= (1.0 + gamma * settings_.mass_damping_per_s) * mass_[d] * v;
      for (Eigen::SparseMatrix<double>::InnerIterator it(K, d); it; ++it) work_a_[it.row()] -= gamma * gamma * it.value() * v;
      if (damping > 0.0)
        for (Eigen::SparseMatrix<double>::InnerIterator it(K0, d); it; ++it) work_a_[it.row()] -= damping * it.value() * v;
    }
    if (extra_ > 0) work_a_ += gamma * q_force;
    for (int d = 0; d < n3; ++d)
      if (dof_[static_cast<std::size_t>(d / 3)] != Dof::Free) work_a_[d] = rv[d];
    if (!factor_in_use_) return 1;  // no setup since the factorisations were dropped: CVODE sets up again
    b = factor_in_use_->solve(work_a_);
  }
  if (!b.allFinite()) return 1;
  for (int d = 0; d < n3; ++d)
    if (dof_[static_cast<std::size_t>(d / 3)] != Dof::Free) b[d] = rv[d];
  z.head(n3) = rx + gamma * b;
  z.segment(n3, n3) = b;
  if (extra_ > 0)
    law_->internal_variable_correction(Eigen::Map<const Eigen::VectorXd>(yp_current_, n3), b, rp + 6 * nodes_, gamma,
                                       zp + 6 * nodes_);
  return 0;
}

int VolumetricNeedleModel::jacobian_times(double, const double*, const double* vp, double* Jvp) {
  const int n3 = 3 * nodes_;
  const Eigen::Map<const Eigen::VectorXd> v(vp, y_.size());
  Eigen::Map<Eigen::VectorXd> Jv(Jvp, y_.size());
  if (!have_tangent_) return -1;
  Jv.head(n3) = v.segment(n3, n3);
  work_a_ = tangent_.matrix() * v.head(n3);
  if (settings_.stiffness_damping_s > 0.0)
    work_a_.noalias() += settings_.stiffness_damping_s * (rest_tangent_.matrix() * v.segment(n3, n3));
  const double alpha = settings_.mass_damping_per_s;
  for (int d = 0; d < n3; ++d)
    Jv[n3 + d] = dof_[static_cast<std::size_t>(d / 3)] == Dof::Free ? -work_a_[d] / mass_[d] - alpha * v[n3 + d] : 0.0;
  return 0;
}

}  // namespace puncture::comparison
