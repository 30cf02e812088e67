#include "puncture/force_mesh.hpp"

#include <Eigen/Geometry>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace puncture {

MeshIntegrator parse_mesh_integrator(const std::string& name) {
  if (name == "quasi_static") return MeshIntegrator::QuasiStatic;
  if (name == "explicit") return MeshIntegrator::Explicit;
  if (name == "implicit") return MeshIntegrator::Implicit;
  throw std::invalid_argument("realtime.integrator must be \"quasi_static\", \"explicit\" or \"implicit\" (got \"" +
                              name + "\")");
}

const char* to_string(MeshIntegrator integrator) {
  switch (integrator) {
    case MeshIntegrator::QuasiStatic: return "quasi_static";
    case MeshIntegrator::Explicit: return "explicit";
    case MeshIntegrator::Implicit: return "implicit";
  }
  return "unknown";
}

namespace {

void require_positive(double value, const char* what) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw std::invalid_argument(std::string("force mesh: ") + what + " must be positive and finite (got " +
                                std::to_string(value) + ")");
}

using SparseMatrix = Eigen::SparseMatrix<double>;

// K_ff + shift * I over the free nodes (node i -> row i - 1).
SparseMatrix free_stiffness(const HexLattice& lat, double K, double ks, double diagonal_shift) {
  const int nf = lat.node_count() - 1;
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<std::size_t>(nf) * 7);
  for (int i = 1; i <= nf; ++i) {
    t.emplace_back(i - 1, i - 1, K + ks * lat.neighbour_count(i) + diagonal_shift);
    for (int k = lat.neighbour_offsets[i]; k < lat.neighbour_offsets[i + 1]; ++k) {
      const int j = lat.neighbours[k];
      if (j != 0) t.emplace_back(i - 1, j - 1, -ks);
    }
  }
  SparseMatrix A(nf, nf);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

}  // namespace

namespace {

/// The constructor's argument checks (std::invalid_argument naming the value).
void check_mesh_arguments(const ForceMeshParams& params, double layer_thickness_m, double density_kg_per_m3,
                          const MeshIntegrationSettings& settings) {
  require_positive(params.virtual_stiffness_N_per_m, "virtual_stiffness_N_per_m (K)");
  require_positive(params.spacing_L_m, "spacing_L_m (L)");
  require_positive(params.deformed_threshold_m, "deformed_threshold_m");
  require_positive(layer_thickness_m, "layer thickness");
  require_positive(density_kg_per_m3, "density");
  require_positive(settings.time_step_s, "time step");
  if (!(params.surface_stiffness_N_per_m >= 0.0) || !std::isfinite(params.surface_stiffness_N_per_m))
    throw std::invalid_argument("force mesh: surface_stiffness_N_per_m must be >= 0 and finite");
  if (!(params.node_damping_N_s_per_m >= 0.0) || !std::isfinite(params.node_damping_N_s_per_m))
    throw std::invalid_argument("force mesh: node_damping_N_s_per_m must be >= 0 and finite");
  if (!(settings.explicit_safety > 0.0 && settings.explicit_safety <= 1.0))
    throw std::invalid_argument("force mesh: explicit_safety must be in (0, 1]");
  if (settings.max_explicit_substeps < 1) throw std::invalid_argument("force mesh: max_explicit_substeps must be >= 1");
  if (!(params.surface_axial_stiffness_N_per_m >= 0.0) || !std::isfinite(params.surface_axial_stiffness_N_per_m))
    throw std::invalid_argument("force mesh: surface_axial_stiffness_N_per_m must be >= 0 and finite");
  if (!(params.virtual_stiffening_m >= 0.0) || !std::isfinite(params.virtual_stiffening_m))
    throw std::invalid_argument("force mesh: virtual_stiffening_m must be >= 0 and finite");
}

}  // namespace

ForceMesh::ForceMesh(const ContactSurface& surface, const SurfacePoint& contact, const ForceMeshParams& params,
                     double layer_thickness_m, double density_kg_per_m3, const MeshIntegrationSettings& settings)
    : params_(params), settings_(settings), lattice_(make_hex_lattice(params.rings_w)) {
  check_mesh_arguments(params, layer_thickness_m, density_kg_per_m3, settings);
  const int n = lattice_.node_count();
  const double L = params.spacing_L_m;
  mass_kg_ = density_kg_per_m3 * layer_thickness_m * 0.5 * std::sqrt(3.0) * L * L;

  rest_.resize(3, n);
  normals_.resize(3, n);
  positions_.resize(3, n);
  z_.setZero(n);
  layout(surface, contact);

  v_.setZero(n);
  pz_.setZero(n);
  pv_.setZero(n);
  rhs_.setZero(n - 1);
  work_.setZero(n - 1);
  ring_mean_m_.setZero(params.rings_w);
  ring_size_.setZero(params.rings_w);
  for (int i = 0; i < n; ++i) ring_size_[lattice_.ring[i] - 1] += 1.0;

  setup_cells();
  // Each ring's nodes in node order and its distinct cells (the ring means of a stiffening mesh).
  ring_node_start_.assign(params.rings_w + 1, 0);
  for (int i = 0; i < n; ++i) ++ring_node_start_[lattice_.ring[i]];
  for (int j = 0; j < params.rings_w; ++j) ring_node_start_[j + 1] += ring_node_start_[j];
  ring_nodes_.resize(n);
  {
    std::vector<int> next(ring_node_start_.begin(), ring_node_start_.end() - 1);
    for (int i = 0; i < n; ++i) ring_nodes_[next[lattice_.ring[i] - 1]++] = i;
  }
  ring_cell_start_.assign(1, 0);
  ring_cells_.clear();
  for (int j = 0; j < params.rings_w; ++j) {
    for (int k = ring_node_start_[j]; k < ring_node_start_[j + 1]; ++k) {
      const int c = cell_of_[ring_nodes_[k]];
      if (std::find(ring_cells_.begin() + ring_cell_start_[j], ring_cells_.end(), c) == ring_cells_.end())
        ring_cells_.push_back(c);
    }
    ring_cell_start_.push_back(static_cast<int>(ring_cells_.size()));
  }
  compute_static_influence();
  choose_integration();
  if (nonlinear_) {
    setup_nonlinear();
    update_derived();
    return;
  }
  if (use_implicit_ && n > 1) factor_implicit_system();
  compute_unit_step_response();
  update_derived();
}

void ForceMesh::compute_static_influence() {
  // Unit-deflection influence vector: K_ff u_f = b.
  const int nf = lattice_.node_count() - 1;
  const double K = params_.virtual_stiffness_N_per_m;
  const double ks = params_.surface_stiffness_N_per_m;
  influence_.setZero(nf + 1);
  influence_[0] = 1.0;
  if (nf > 0) {
    Eigen::VectorXd b = Eigen::VectorXd::Zero(nf);
    for (int k = lattice_.neighbour_offsets[0]; k < lattice_.neighbour_offsets[1]; ++k)
      b[lattice_.neighbours[k] - 1] = ks;
    Eigen::SimplicialLDLT<SparseMatrix> static_solver(free_stiffness(lattice_, K, ks, 0.0));
    if (static_solver.info() != Eigen::Success)
      throw std::runtime_error("force mesh: static stiffness matrix could not be factorised");
    influence_.tail(nf) = static_solver.solve(b);
  }
  static_stiffness_N_per_m_ = K;
  for (int k = lattice_.neighbour_offsets[0]; k < lattice_.neighbour_offsets[1]; ++k)
    static_stiffness_N_per_m_ += ks * (1.0 - influence_[lattice_.neighbours[k]]);
}

void ForceMesh::choose_integration() {
  // Explicit stability: Gershgorin bound on omega_max^2.
  const int n = lattice_.node_count();
  const double K = params_.virtual_stiffness_N_per_m;
  const double ks = params_.surface_stiffness_N_per_m;
  const double c = params_.node_damping_N_s_per_m;
  int max_degree = 0;
  for (int i = 1; i < n; ++i) max_degree = std::max(max_degree, lattice_.neighbour_count(i));
  omega_max_sq_ = (K + 2.0 * ks * max_degree) / mass_kg_;
  const double cm = c / mass_kg_;
  // Root of omega^2 dt^2 + 2 (c/m) dt = 4 (Jury condition of the damped symplectic Euler step).
  dt_crit_s_ = (-cm + std::sqrt(cm * cm + 4.0 * omega_max_sq_)) / omega_max_sq_;
  if (c > 0.0) dt_crit_s_ = std::min(dt_crit_s_, 2.0 / cm);
  const double dt = settings_.time_step_s;
  const double substeps_needed = std::ceil(dt / (settings_.explicit_safety * dt_crit_s_));
  substeps_ = static_cast<int>(std::min<double>(std::max(1.0, substeps_needed), settings_.max_explicit_substeps + 1.0));
  explicit_fallback_ = substeps_needed > settings_.max_explicit_substeps;
  nonlinear_ = params_.nonlinear();
  if (nonlinear_ && settings_.integrator == MeshIntegrator::Explicit) explicit_fallback_ = true;  // see the header
  use_implicit_ = settings_.integrator == MeshIntegrator::Implicit ||
                  (settings_.integrator == MeshIntegrator::Explicit && explicit_fallback_);
}

void ForceMesh::factor_implicit_system() {
  // Backward Euler on the lattice's cells (every free node's equation is its
  // cell's; see "Stiffening in the mesh" in the header): row a = cell - 1
  // times the cell's size, so that the matrix is symmetric.
  const int mf = static_cast<int>(cell_size_.size()) - 1;
  const double dt = settings_.time_step_s;
  const double shift = mass_kg_ / (dt * dt) + params_.node_damping_N_s_per_m / dt;
  const double K = params_.virtual_stiffness_N_per_m, ks = params_.surface_stiffness_N_per_m;
  std::vector<Eigen::Triplet<double>> t;
  for (int a = 1; a <= mf; ++a) t.emplace_back(a - 1, a - 1, cell_size_[a] * (K + shift));
  for (const CellPair& p : pairs_) {
    t.emplace_back(p.a - 1, p.a - 1, p.edges * ks);
    t.emplace_back(p.b - 1, p.b - 1, p.edges * ks);
    t.emplace_back(p.a - 1, p.b - 1, -p.edges * ks);
    t.emplace_back(p.b - 1, p.a - 1, -p.edges * ks);
  }
  for (const CellPair& p : contact_pairs_) t.emplace_back(p.b - 1, p.b - 1, p.edges * ks);
  SparseMatrix A(mf, mf);
  A.setFromTriplets(t.begin(), t.end());
  Eigen::SimplicialLDLT<SparseMatrix> ldlt(A);
  if (ldlt.info() != Eigen::Success)
    throw std::runtime_error("force mesh: implicit system matrix could not be factorised");
  // Copy the factors into plain arrays so that a step is allocation-free.
  // Strictly below the (unit) diagonal, column by column in row order.
  SparseMatrix Lm = ldlt.matrixL();
  Lm.makeCompressed();
  l_col_start_.assign(1, 0);
  l_row_.clear();
  l_val_.clear();
  for (int j = 0; j < mf; ++j) {
    for (SparseMatrix::InnerIterator it(Lm, j); it; ++it)
      if (it.row() > j) l_row_.push_back(static_cast<int>(it.row())), l_val_.push_back(it.value());
    l_col_start_.push_back(static_cast<int>(l_row_.size()));
  }
  d_inv_ = ldlt.vectorD().cwiseInverse();
  perm_.resize(mf);
  for (int k = 0; k < mf; ++k) perm_[k] = ldlt.permutationP().indices()[k];
}

void ForceMesh::compute_unit_step_response() {
  // One step from rest with z0 = 0 -> 1 (the step is affine in z0).
  step_free_nodes(0.0, 1.0);
  qz_ = z_;
  qv_ = v_;
  qz_[0] = 1.0;
  qv_[0] = 0.0;
  z_.setZero();
  v_.setZero();
  reaction_slope_N_per_m_ = params_.virtual_stiffness_N_per_m;
  for (int k = lattice_.neighbour_offsets[0]; k < lattice_.neighbour_offsets[1]; ++k)
    reaction_slope_N_per_m_ += params_.surface_stiffness_N_per_m * (1.0 - qz_[lattice_.neighbours[k]]);
}

void ForceMesh::set_frame(const SurfacePoint& contact) {
  // Tangent plane of the contact point.
  Eigen::Vector3d nrm = contact.normal;
  if (!(nrm.norm() > 0.0) || !nrm.allFinite() || !contact.position.allFinite())
    throw std::invalid_argument("force mesh: contact point or normal is not finite");
  nrm.normalize();
  const Eigen::Vector3d helper = std::abs(nrm.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  frame_origin_ = contact.position;
  frame_normal_ = nrm;
  frame_e1_ = (helper - helper.dot(nrm) * nrm).normalized();
  frame_e2_ = nrm.cross(frame_e1_);
}

void ForceMesh::project_node(int i) {
  const Eigen::Vector2d p = lattice_.planar_position(i, params_.spacing_L_m);
  const SurfacePoint sp = layout_surface_->project(frame_origin_ + p.x() * frame_e1_ + p.y() * frame_e2_);
  if (!sp.position.allFinite() || !sp.normal.allFinite() || !(sp.normal.norm() > 0.0))
    throw std::invalid_argument("force mesh: projecting node " + std::to_string(i) +
                                " onto the layer surface gave a non-finite point");
  rest_.col(i) = sp.position;
  normals_.col(i) = sp.normal.normalized();
  // Stale positions are all recomputed when asked (positions()); fresh ones imply fresh nodes.
  if (!positions_stale_) positions_.col(i) = rest_.col(i) - z_[i] * normals_.col(i);
}

void ForceMesh::layout(const ContactSurface& surface, const SurfacePoint& contact) {
  // Every node projected onto the surface at once (construction).
  set_frame(contact);
  layout_surface_ = &surface;
  rest_.col(0) = contact.position;
  normals_.col(0) = frame_normal_;
  positions_.col(0) = rest_.col(0);
  for (int i = 1; i < lattice_.node_count(); ++i) project_node(i);
  next_projection_ = lattice_.node_count();
  positions_ = rest_;
  positions_stale_ = false;
}

const Eigen::Matrix3Xd& ForceMesh::positions() const {
  if (positions_stale_) {
    update_nodes();
    for (int i = 0; i < lattice_.node_count(); ++i) positions_.col(i) = rest_.col(i) - z_[i] * normals_.col(i);
    positions_stale_ = false;
  }
  return positions_;
}

void ForceMesh::relayout(const ContactSurface& surface, const SurfacePoint& contact) {
  set_frame(contact);
  layout_surface_ = &surface;
  rest_.col(0) = contact.position;
  normals_.col(0) = frame_normal_;
  for (int i = 1; i < lattice_.node_count(); ++i) {
    const Eigen::Vector2d p = lattice_.planar_position(i, params_.spacing_L_m);
    rest_.col(i) = frame_origin_ + p.x() * frame_e1_ + p.y() * frame_e2_;
    normals_.col(i) = frame_normal_;
  }
  next_projection_ = 1;
  reset();
}

int ForceMesh::refine_layout(int max_nodes) {
  const int n = lattice_.node_count();
  for (int k = 0; k < max_nodes && next_projection_ < n; ++k) project_node(next_projection_++);
  return n - next_projection_;
}

bool ForceMesh::laid_at(const SurfacePoint& contact, double tolerance_m) const {
  return (rest_.col(0) - contact.position).norm() <= tolerance_m &&
         (normals_.col(0) - contact.normal.normalized()).norm() <= 1e-9;
}

void ForceMesh::reset() {
  z_.setZero();
  v_.setZero();
  nodes_stale_ = false;
  if (nonlinear_) {
    cell_state_z_.setZero();
    cell_state_v_.setZero();
  }
  predicted_ = false;
  predicted_z0_ = 0.0;
  update_derived();
}

void ForceMesh::explicit_substep(double dt, double z0) {
  const double K = params_.virtual_stiffness_N_per_m;
  const double ks = params_.surface_stiffness_N_per_m;
  const double c = params_.node_damping_N_s_per_m;
  const int n = lattice_.node_count();
  z_[0] = z0;
  // Symplectic Euler: all accelerations from the old deflections, then v, then z.
  for (int i = 1; i < n; ++i) {
    double f = -K * z_[i] - c * v_[i];
    for (int k = lattice_.neighbour_offsets[i]; k < lattice_.neighbour_offsets[i + 1]; ++k)
      f -= ks * (z_[i] - z_[lattice_.neighbours[k]]);
    work_[i - 1] = f / mass_kg_;
  }
  for (int i = 1; i < n; ++i) {
    v_[i] += dt * work_[i - 1];
    z_[i] += dt * v_[i];
  }
}

void ForceMesh::implicit_solve() {
  const int nf = static_cast<int>(cell_size_.size()) - 1;  // one equation per free cell
  // Solve P^T L D L^T P x = rhs_ into work_.
  for (int k = 0; k < nf; ++k) work_[perm_[k]] = rhs_[k];
  for (int j = 0; j < nf; ++j) {
    const double yj = work_[j];
    for (int p = l_col_start_[j]; p < l_col_start_[j + 1]; ++p) work_[l_row_[p]] -= l_val_[p] * yj;
  }
  for (int j = 0; j < nf; ++j) work_[j] *= d_inv_[j];
  for (int j = nf - 1; j >= 0; --j) {
    double s = work_[j];
    for (int p = l_col_start_[j]; p < l_col_start_[j + 1]; ++p) s -= l_val_[p] * work_[l_row_[p]];
    work_[j] = s;
  }
}

void ForceMesh::step_free_nodes(double z0_old, double z0_new) {
  const int n = lattice_.node_count();
  const int nf = n - 1;
  const double dt = settings_.time_step_s;
  if (settings_.integrator == MeshIntegrator::QuasiStatic) {
    for (int i = 1; i < n; ++i) z_[i] = influence_[i] * z0_new, v_[i] = 0.0;
  } else if (!use_implicit_) {
    const double h = dt / substeps_;
    for (int s = 1; s <= substeps_; ++s) explicit_substep(h, z0_old + (z0_new - z0_old) * s / substeps_);
  } else if (nf > 0) {
    const double m_dt2 = mass_kg_ / (dt * dt);
    const double c_dt = params_.node_damping_N_s_per_m / dt;
    const double ks = params_.surface_stiffness_N_per_m;
    // Per free cell (its first node's state; the state is constant on the
    // cells), times its size: rhs = M/dt^2 (z + dt v) + C/dt z + b z0.
    const int nc = static_cast<int>(cell_size_.size());
    for (int a = 1; a < nc; ++a) {
      const int i = cell_rep_[a];
      rhs_[a - 1] = cell_size_[a] * (m_dt2 * (z_[i] + dt * v_[i]) + c_dt * z_[i]);
    }
    for (const CellPair& p : contact_pairs_) rhs_[p.b - 1] += p.edges * ks * z0_new;
    implicit_solve();
    for (int i = 1; i < n; ++i) {
      const double z_new = work_[perm_[cell_of_[i] - 1]];
      v_[i] = (z_new - z_[i]) / dt;
      z_[i] = z_new;
    }
  }
  z_[0] = z0_new;
}

void ForceMesh::predict() {
  if (nonlinear_) {
    predict_nonlinear(cell_state_z_[0]);
    return;
  }
  predict_linear();
}

void ForceMesh::predict_linear() {
  // The step from the committed state with z0 = 0 at its end, in the scratch
  // vectors; the committed state is swapped back in afterwards.
  const double z0_old = z_[0];
  pz_ = z_;
  pv_ = v_;
  z_.swap(pz_);
  v_.swap(pv_);  // (z_, v_) = copies; (pz_, pv_) = committed state
  step_free_nodes(z0_old, 0.0);
  z_.swap(pz_);
  v_.swap(pv_);  // (z_, v_) = committed state again; (pz_, pv_) = predicted
  double f = 0.0;
  for (int k = lattice_.neighbour_offsets[0]; k < lattice_.neighbour_offsets[1]; ++k)
    f -= params_.surface_stiffness_N_per_m * pz_[lattice_.neighbours[k]];
  predicted_intercept_N_ = f;
  predicted_ = true;
}

namespace {

/// One step's state (z, v) from its prediction: entries 1.. at contact
/// deflection z0 = predicted + dz0 (p + dz0 q), entry 0 the contact itself.
/// Per node for a linear mesh, per lattice cell for a stiffening one.
void commit_predicted(Eigen::VectorXd& z, Eigen::VectorXd& v, const Eigen::VectorXd& pz, const Eigen::VectorXd& pv,
                      const Eigen::VectorXd& qz, const Eigen::VectorXd& qv, double dz0, double z0, double dt) {
  const double z0_old = z[0];
  for (Eigen::Index i = 1; i < z.size(); ++i) {
    z[i] = pz[i] + dz0 * qz[i];
    v[i] = pv[i] + dz0 * qv[i];
  }
  z[0] = z0;
  v[0] = (z0 - z0_old) / dt;
}

}  // namespace

void ForceMesh::commit(double contact_deflection_m) {
  if (!std::isfinite(contact_deflection_m)) throw std::runtime_error("force mesh: non-finite contact deflection");
  if (!predicted_) predict();
  const double z0 = std::max(0.0, contact_deflection_m);
  const double dz0 = z0 - predicted_z0_;  // predicted_z0_ = 0 for a linear mesh
  const double dt = settings_.time_step_s;
  if (nonlinear_) {  // the state on the cells; the nodes follow when asked (update_nodes)
    commit_predicted(cell_state_z_, cell_state_v_, cell_pz_, cell_pv_, cell_qz_, cell_qv_, dz0, z0, dt);
    nodes_stale_ = true;
  } else {
    commit_predicted(z_, v_, pz_, pv_, qz_, qv_, dz0, z0, dt);
  }
  predicted_ = false;
  update_derived();
  const bool finite = nonlinear_ ? cell_state_z_.allFinite() && cell_state_v_.allFinite()
                                 : std::isfinite(ring_mean_m_.sum()) && std::isfinite(v_.sum());
  if (!finite)
    throw std::runtime_error("force mesh: deflections became non-finite (integrator " +
                             std::string(to_string(settings_.integrator)) + ")");
}

void ForceMesh::advance(double contact_deflection_m) {
  // A stiffening mesh's step is solved at the prescribed deflection itself (no linearisation error).
  if (nonlinear_ && std::isfinite(contact_deflection_m)) predict_nonlinear(std::max(0.0, contact_deflection_m));
  else predict();
  commit(contact_deflection_m);
}

void ForceMesh::update_derived() {
  positions_stale_ = true;
  if (nonlinear_) {
    // The nodes' values are their cells': the same extremes; the ring means when asked.
    ring_means_stale_ = true;
    max_abs_deflection_m_ = cell_state_z_.cwiseAbs().maxCoeff();
    max_abs_velocity_m_per_s_ = cell_state_v_.cwiseAbs().maxCoeff();
    return;
  }
  const int n = lattice_.node_count();
  ring_mean_m_.setZero();
  for (int i = 0; i < n; ++i) ring_mean_m_[lattice_.ring[i] - 1] += z_[i];
  ring_mean_m_.array() /= ring_size_.array();
  max_abs_deflection_m_ = z_.cwiseAbs().maxCoeff();
  max_abs_velocity_m_per_s_ = v_.cwiseAbs().maxCoeff();
}

void ForceMesh::update_nodes() const {
  if (!nodes_stale_) return;
  const int n = lattice_.node_count();
  for (int i = 0; i < n; ++i) {
    const int a = cell_of_[i];
    z_[i] = cell_state_z_[a];
    v_[i] = cell_state_v_[a];
  }
  nodes_stale_ = false;
}

double ForceMesh::ring_mean_from_cells(int j) const {
  // The sum in node order, as update_derived() forms it for a linear mesh.
  double sum = 0.0;
  for (int k = ring_node_start_[j]; k < ring_node_start_[j + 1]; ++k) sum += cell_state_z_[cell_of_[ring_nodes_[k]]];
  return sum / ring_size_[j];
}

void ForceMesh::update_ring_means() const {
  if (!ring_means_stale_) return;
  for (int j = 0; j < params_.rings_w; ++j) ring_mean_m_[j] = ring_mean_from_cells(j);
  ring_means_stale_ = false;
}

double ForceMesh::contact_reaction_N() const {
  update_nodes();
  if (nonlinear_) {
    double f = virtual_spring_force_N(params_, z_[0]);
    for (int k = lattice_.neighbour_offsets[0]; k < lattice_.neighbour_offsets[1]; ++k)
      f += surface_spring_force_N(params_, z_[0] - z_[lattice_.neighbours[k]]);
    return f;
  }
  double f = params_.virtual_stiffness_N_per_m * z_[0];
  for (int k = lattice_.neighbour_offsets[0]; k < lattice_.neighbour_offsets[1]; ++k)
    f += params_.surface_stiffness_N_per_m * (z_[0] - z_[lattice_.neighbours[k]]);
  return f;
}

double ForceMesh::eq5_force_N() const {
  update_nodes();
  update_ring_means();
  if (params_.virtual_stiffening_m > 0.0) {
    double f = 0.0;
    for (int i = 0; i < lattice_.node_count(); ++i) f += virtual_spring_force_N(params_, z_[i]);
    return f;
  }
  double f = ring_mean_m_[0];
  for (int j = 2; j <= params_.rings_w; ++j) f += 6.0 * (j - 1) * ring_mean_m_[j - 1];
  return params_.virtual_stiffness_N_per_m * f;
}

int ForceMesh::deformed_rings() const {
  const double threshold = params_.deformed_threshold_m;
  int j = 0;
  if (nonlinear_ && ring_means_stale_) {
    // Per tick: a ring whose cells all lie clearly on one side of the threshold
    // needs no sum (the rounded mean of values in [lo, hi] lies within
    // 1e-10 max(|lo|, |hi|) of that range); the others are summed exactly.
    for (; j < params_.rings_w; ++j) {
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (int k = ring_cell_start_[j]; k < ring_cell_start_[j + 1]; ++k) {
        lo = std::min(lo, cell_state_z_[ring_cells_[k]]);
        hi = std::max(hi, cell_state_z_[ring_cells_[k]]);
      }
      const double margin = 1e-10 * std::max(std::abs(lo), std::abs(hi));
      if (lo > threshold + margin) continue;
      if (hi < threshold - margin || !(ring_mean_from_cells(j) > threshold)) break;
    }
    return j;
  }
  while (j < params_.rings_w && ring_mean_m_[j] > threshold) ++j;
  return j;
}

double ForceMesh::kinetic_energy_J() const {
  // Free nodes only: the contact node moves with the needle.
  update_nodes();
  return 0.5 * mass_kg_ * v_.tail(v_.size() - 1).squaredNorm();
}

double ForceMesh::virtual_spring_energy_J() const {
  update_nodes();
  if (params_.virtual_stiffening_m > 0.0) {
    double e = 0.0;
    for (int i = 0; i < lattice_.node_count(); ++i) e += puncture::virtual_spring_energy_J(params_, z_[i]);
    return e;
  }
  return 0.5 * params_.virtual_stiffness_N_per_m * z_.squaredNorm();
}

double ForceMesh::surface_spring_energy_J() const {
  update_nodes();
  double e = 0.0;
  if (params_.surface_axial_stiffness_N_per_m > 0.0) {
    for (int i = 0; i < lattice_.node_count(); ++i)
      for (int k = lattice_.neighbour_offsets[i]; k < lattice_.neighbour_offsets[i + 1]; ++k) {
        const int j = lattice_.neighbours[k];
        if (j > i) e += puncture::surface_spring_energy_J(params_, z_[i] - z_[j]);
      }
    return e;
  }
  const int n = lattice_.node_count();
  for (int i = 0; i < n; ++i)
    for (int k = lattice_.neighbour_offsets[i]; k < lattice_.neighbour_offsets[i + 1]; ++k) {
      const int j = lattice_.neighbours[k];
      if (j > i) e += (z_[i] - z_[j]) * (z_[i] - z_[j]);
    }
  return 0.5 * params_.surface_stiffness_N_per_m * e;
}

}  // namespace puncture
