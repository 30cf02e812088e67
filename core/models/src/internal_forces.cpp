// internal_forces.cpp: mass-spring, linear, StVK and visco-elastic tensor-mass
// forces on a tetrahedral mesh; see internal_forces.hpp.
#include "puncture/comparison/internal_forces.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

namespace puncture::comparison {

namespace {

constexpr int kTetEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

Matrix34d rest_positions(const TetMesh& mesh, int t) {
  Matrix34d X;
  for (int a = 0; a < 4; ++a) X.col(a) = mesh.points_m.col(mesh.tets[static_cast<std::size_t>(t)][a]);
  return X;
}

const LayerElasticity& layer_of(const std::vector<LayerElasticity>& layers, const TetMesh& mesh, int t) {
  const int k = mesh.layer[static_cast<std::size_t>(t)];
  if (k < 0 || k >= static_cast<int>(layers.size()))
    throw std::invalid_argument("internal forces: tetrahedron " + std::to_string(t) + " has layer " +
                                std::to_string(k) + " but " + std::to_string(layers.size()) + " layers are given");
  return layers[static_cast<std::size_t>(k)];
}

Eigen::Vector3d segment(VectorRef x, int a) { return x.segment<3>(3 * a); }

template <class Vector>
std::size_t bytes_of(const Vector& v) {
  return v.capacity() * sizeof(typename Vector::value_type);
}

}  // namespace

std::vector<std::pair<int, int>> tet_edges(const TetMesh& mesh) {
  std::vector<std::pair<int, int>> edges;
  edges.reserve(mesh.tets.size() * 6);
  for (const Eigen::Vector4i& t : mesh.tets)
    for (const auto& e : kTetEdges) {
      int a = t[e[0]], b = t[e[1]];
      if (a > b) std::swap(a, b);
      edges.emplace_back(a, b);
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

std::vector<std::pair<int, int>> tet_node_pairs(const TetMesh& mesh) { return tet_edges(mesh); }

// ---------------------------------------------------------------------------- mass-spring

SpringKind parse_spring_kind(const std::string& name) {
  if (name == "linear") return SpringKind::Linear;
  if (name == "nonlinear") return SpringKind::Nonlinear;
  throw std::invalid_argument("unknown spring kind '" + name + "' (known: linear, nonlinear)");
}

const char* to_string(SpringKind kind) { return kind == SpringKind::Linear ? "linear" : "nonlinear"; }

MassSpringLaw::MassSpringLaw(const TetMesh& mesh, const std::vector<LayerElasticity>& layers,
                             std::vector<double> layer_scale, SpringKind kind)
    : mesh_(&mesh), layers_(layers), layer_scale_(std::move(layer_scale)), edges_(tet_edges(mesh)), kind_(kind) {
  if (layer_scale_.empty()) layer_scale_.assign(layers_.size(), 1.0);
  if (layer_scale_.size() != layers_.size())
    throw std::invalid_argument("MassSpringLaw: " + std::to_string(layer_scale_.size()) + " stiffness scales for " +
                                std::to_string(layers_.size()) + " layers");
  for (double s : layer_scale_)
    if (!(s > 0.0) || !std::isfinite(s)) throw std::invalid_argument("MassSpringLaw: stiffness scales must be > 0");
  rest_length_.resize(edges_.size());
  rest_direction_.resize(edges_.size());
  for (std::size_t e = 0; e < edges_.size(); ++e) {
    const Eigen::Vector3d d = mesh.points_m.col(edges_[e].second) - mesh.points_m.col(edges_[e].first);
    rest_length_[e] = d.norm();
    if (!(rest_length_[e] > 0.0))
      throw std::invalid_argument("MassSpringLaw: edge " + std::to_string(edges_[e].first) + "-" +
                                  std::to_string(edges_[e].second) + " has zero rest length");
    rest_direction_[e] = d / rest_length_[e];
  }
  compute_stiffness(std::vector<std::uint8_t>(mesh.tets.size(), 0));
}

void MassSpringLaw::compute_stiffness(const std::vector<std::uint8_t>& removed) {
  // k_e = sum over the tetrahedra T containing e of s_layer(T) E(T) V_T / l_e^2.
  stiffness_.assign(edges_.size(), 0.0);
  for (int t = 0; t < mesh_->tet_count(); ++t) {
    if (removed[static_cast<std::size_t>(t)]) continue;
    const LayerElasticity& layer = layer_of(layers_, *mesh_, t);
    const double volume = tet_shape(rest_positions(*mesh_, t)).volume_m3;
    const double EV = layer_scale_[static_cast<std::size_t>(mesh_->layer[static_cast<std::size_t>(t)])] *
                      layer.youngs_modulus_Pa * volume;
    const Eigen::Vector4i& v = mesh_->tets[static_cast<std::size_t>(t)];
    for (const auto& local : kTetEdges) {
      std::pair<int, int> e(v[local[0]], v[local[1]]);
      if (e.first > e.second) std::swap(e.first, e.second);
      const auto it = std::lower_bound(edges_.begin(), edges_.end(), e);
      const std::size_t index = static_cast<std::size_t>(it - edges_.begin());
      stiffness_[index] += EV / (rest_length_[index] * rest_length_[index]);
    }
  }
}

void MassSpringLaw::add_forces(VectorRef x, VectorRef, const double*, MutableVectorRef f,
                               double*) const {
  for (std::size_t e = 0; e < edges_.size(); ++e) {
    const double k = stiffness_[e];
    if (k == 0.0) continue;
    const int a = edges_[e].first, b = edges_[e].second;
    const Eigen::Vector3d d = segment(x, b) - segment(x, a);
    if (kind_ == SpringKind::Linear) {
      // Stretch along the rest direction: n0 . (d - d0) = n0 . d - l0.
      const Eigen::Vector3d force = k * (rest_direction_[e].dot(d) - rest_length_[e]) * rest_direction_[e];
      f.segment<3>(3 * a) += force;
      f.segment<3>(3 * b) -= force;
      continue;
    }
    const double length = d.norm();
    if (!(length > 0.0)) continue;
    const Eigen::Vector3d force = k * (length - rest_length_[e]) / length * d;  // pulls a toward b when stretched
    f.segment<3>(3 * a) += force;
    f.segment<3>(3 * b) -= force;
  }
}

void MassSpringLaw::add_tangent(VectorRef x, double gamma, NodeBlockMatrix& K) const {
  for (std::size_t e = 0; e < edges_.size(); ++e) {
    const double k = stiffness_[e];
    if (k == 0.0) continue;
    const int a = edges_[e].first, b = edges_[e].second;
    if (kind_ == SpringKind::Linear) {
      const Eigen::Matrix3d block = k * rest_direction_[e] * rest_direction_[e].transpose();
      K.add_block(a, a, block);
      K.add_block(b, b, block);
      K.add_block(a, b, -block);
      K.add_block(b, a, -block);
      continue;
    }
    const Eigen::Vector3d d = segment(x, b) - segment(x, a);
    const double length = d.norm();
    if (!(length > 0.0)) continue;
    const Eigen::Vector3d n = d / length;
    const Eigen::Matrix3d nn = n * n.transpose();
    // d(force on a)/dx_b = k [n n^T + (1 - l0/l)(I - n n^T)]. For the implicit
    // integrator (gamma > 0) the transverse part is kept >= 0 (a compressed
    // spring's negative geometric stiffness is left out of the preconditioner,
    // which stays positive definite); a static solve (gamma = 0) gets the exact
    // tangent.
    const double transverse = gamma > 0.0 ? std::max(0.0, 1.0 - rest_length_[e] / length) : 1.0 - rest_length_[e] / length;
    const Eigen::Matrix3d block = k * (nn + transverse * (Eigen::Matrix3d::Identity() - nn));
    K.add_block(a, a, block);
    K.add_block(b, b, block);
    K.add_block(a, b, -block);
    K.add_block(b, a, -block);
  }
}

double MassSpringLaw::energy_J(VectorRef x) const {
  double energy = 0.0;
  for (std::size_t e = 0; e < edges_.size(); ++e) {
    const Eigen::Vector3d d = segment(x, edges_[e].second) - segment(x, edges_[e].first);
    const double stretch = (kind_ == SpringKind::Linear ? rest_direction_[e].dot(d) : d.norm()) - rest_length_[e];
    energy += 0.5 * stiffness_[e] * stretch * stretch;
  }
  return energy;
}

void MassSpringLaw::set_removed(const std::vector<std::uint8_t>& removed) {
  if (removed.size() != mesh_->tets.size()) throw std::invalid_argument("MassSpringLaw::set_removed: wrong mask size");
  compute_stiffness(removed);
}

std::size_t MassSpringLaw::memory_bytes() const {
  return bytes_of(edges_) + bytes_of(rest_length_) + bytes_of(rest_direction_) + bytes_of(stiffness_) +
         bytes_of(layer_scale_);
}

// ---------------------------------------------------------------------------- linear tensor-mass

LinearTensorMass::LinearTensorMass(const TetMesh& mesh, const std::vector<LayerElasticity>& layers)
    : mesh_(&mesh), layers_(layers), edges_(tet_edges(mesh)) {
  rest_ = Eigen::Map<const Eigen::VectorXd>(mesh.points_m.data(), mesh.points_m.size());
  compute_tensors(std::vector<std::uint8_t>(mesh.tets.size(), 0));
}

void LinearTensorMass::compute_tensors(const std::vector<std::uint8_t>& removed) {
  vertex_.assign(static_cast<std::size_t>(mesh_->node_count()), Eigen::Matrix3d::Zero());
  edge_.assign(edges_.size(), Eigen::Matrix3d::Zero());
  for (int t = 0; t < mesh_->tet_count(); ++t) {
    if (removed[static_cast<std::size_t>(t)]) continue;
    const LayerElasticity& layer = layer_of(layers_, *mesh_, t);
    const LameParameters lame = lame_from_young(layer.youngs_modulus_Pa, layer.poisson_ratio);
    const TetShape shape = tet_shape(rest_positions(*mesh_, t));
    const Eigen::Vector4i& v = mesh_->tets[static_cast<std::size_t>(t)];
    for (int a = 0; a < 4; ++a) {
      vertex_[static_cast<std::size_t>(v[a])] += linear_stiffness_block(shape, lame, a, a);
      for (int b = a + 1; b < 4; ++b) {
        // Stored for the ordered pair (min, max): K_{min,max}.
        const bool ordered = v[a] < v[b];
        const std::pair<int, int> e(std::min(v[a], v[b]), std::max(v[a], v[b]));
        const auto it = std::lower_bound(edges_.begin(), edges_.end(), e);
        edge_[static_cast<std::size_t>(it - edges_.begin())] +=
            ordered ? linear_stiffness_block(shape, lame, a, b) : linear_stiffness_block(shape, lame, b, a);
      }
    }
  }
}

void LinearTensorMass::add_forces(VectorRef x, VectorRef, const double*, MutableVectorRef f,
                                  double*) const {
  const int n = mesh_->node_count();
  for (int a = 0; a < n; ++a)
    f.segment<3>(3 * a) -= vertex_[static_cast<std::size_t>(a)] * (x.segment<3>(3 * a) - rest_.segment<3>(3 * a));
  for (std::size_t e = 0; e < edges_.size(); ++e) {
    const int a = edges_[e].first, b = edges_[e].second;
    const Eigen::Matrix3d& K = edge_[e];
    f.segment<3>(3 * a) -= K * (x.segment<3>(3 * b) - rest_.segment<3>(3 * b));
    f.segment<3>(3 * b) -= K.transpose() * (x.segment<3>(3 * a) - rest_.segment<3>(3 * a));
  }
}

void LinearTensorMass::add_tangent(VectorRef, double, NodeBlockMatrix& K) const {
  for (int a = 0; a < mesh_->node_count(); ++a) K.add_block(a, a, vertex_[static_cast<std::size_t>(a)]);
  for (std::size_t e = 0; e < edges_.size(); ++e) {
    K.add_block(edges_[e].first, edges_[e].second, edge_[e]);
    K.add_block(edges_[e].second, edges_[e].first, edge_[e].transpose());
  }
}

double LinearTensorMass::energy_J(VectorRef x) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  add_forces(x, x, nullptr, f, nullptr);
  return -0.5 * f.dot(x - rest_);
}

void LinearTensorMass::set_removed(const std::vector<std::uint8_t>& removed) {
  if (removed.size() != mesh_->tets.size())
    throw std::invalid_argument("LinearTensorMass::set_removed: wrong mask size");
  compute_tensors(removed);
}

std::size_t LinearTensorMass::memory_bytes() const {
  return bytes_of(edges_) + bytes_of(vertex_) + bytes_of(edge_) + static_cast<std::size_t>(rest_.size()) * sizeof(double);
}

// ---------------------------------------------------------------------------- StVK tensor-mass

StvkTensorMass::StvkTensorMass(const TetMesh& mesh, const std::vector<LayerElasticity>& layers)
    : mesh_(&mesh), removed_(mesh.tets.size(), 0) {
  shape_.reserve(mesh.tets.size());
  lame_.reserve(mesh.tets.size());
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const LayerElasticity& layer = layer_of(layers, mesh, t);
    shape_.push_back(tet_shape(rest_positions(mesh, t)));
    lame_.push_back(lame_from_young(layer.youngs_modulus_Pa, layer.poisson_ratio));
  }
}

Matrix34d StvkTensorMass::element_positions(VectorRef x, int t) const {
  Matrix34d xe;
  const Eigen::Vector4i& v = mesh_->tets[static_cast<std::size_t>(t)];
  for (int a = 0; a < 4; ++a) xe.col(a) = x.segment<3>(3 * v[a]);
  return xe;
}

void StvkTensorMass::add_forces(VectorRef x, VectorRef, const double*, MutableVectorRef f,
                                double*) const {
  for (int t = 0; t < mesh_->tet_count(); ++t) {
    if (removed_[static_cast<std::size_t>(t)]) continue;
    const Matrix34d fe = stvk_forces(shape_[static_cast<std::size_t>(t)], element_positions(x, t),
                                     lame_[static_cast<std::size_t>(t)]);
    const Eigen::Vector4i& v = mesh_->tets[static_cast<std::size_t>(t)];
    for (int a = 0; a < 4; ++a) f.segment<3>(3 * v[a]) += fe.col(a);
  }
}

void StvkTensorMass::add_tangent(VectorRef x, double, NodeBlockMatrix& K) const {
  for (int t = 0; t < mesh_->tet_count(); ++t) {
    if (removed_[static_cast<std::size_t>(t)]) continue;
    const Matrix12d Ke = stvk_tangent(shape_[static_cast<std::size_t>(t)], element_positions(x, t),
                                      lame_[static_cast<std::size_t>(t)]);
    const Eigen::Vector4i& v = mesh_->tets[static_cast<std::size_t>(t)];
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) K.add_block(v[a], v[b], Ke.block<3, 3>(3 * a, 3 * b));
  }
}

double StvkTensorMass::energy_J(VectorRef x) const {
  double energy = 0.0;
  for (int t = 0; t < mesh_->tet_count(); ++t)
    if (!removed_[static_cast<std::size_t>(t)])
      energy += stvk_energy_J(shape_[static_cast<std::size_t>(t)], element_positions(x, t),
                              lame_[static_cast<std::size_t>(t)]);
  return energy;
}

void StvkTensorMass::set_removed(const std::vector<std::uint8_t>& removed) {
  if (removed.size() != mesh_->tets.size()) throw std::invalid_argument("StvkTensorMass::set_removed: wrong mask size");
  removed_ = removed;
}

std::size_t StvkTensorMass::memory_bytes() const { return bytes_of(shape_) + bytes_of(lame_) + bytes_of(removed_); }

// ---------------------------------------------------------------------------- visco-elastic tensor-mass

namespace {
/// Symmetric 3 x 3 <-> 6 numbers (xx, yy, zz, yz, xz, xy).
Eigen::Matrix3d from_voigt(const double* q) {
  Eigen::Matrix3d S;
  S << q[0], q[5], q[4], q[5], q[1], q[3], q[4], q[3], q[2];
  return S;
}
void to_voigt(const Eigen::Matrix3d& S, double* q) {
  q[0] = S(0, 0), q[1] = S(1, 1), q[2] = S(2, 2), q[3] = S(1, 2), q[4] = S(0, 2), q[5] = S(0, 1);
}
}  // namespace

ViscoelasticTensorMass::ViscoelasticTensorMass(const TetMesh& mesh, const std::vector<LayerElasticity>& layers,
                                               PronySeries prony)
    : StvkTensorMass(mesh, layers), prony_(std::move(prony)) {
  if (prony_.g.size() != prony_.tau_s.size())
    throw std::invalid_argument("ViscoelasticTensorMass: prony g and tau must have the same length");
  for (std::size_t k = 0; k < prony_.g.size(); ++k)
    if (!(prony_.g[k] >= 0.0) || !(prony_.tau_s[k] > 0.0))
      throw std::invalid_argument("ViscoelasticTensorMass: need g_k >= 0 and tau_k > 0");
  double smallest = 0.0;
  for (const LayerElasticity& l : layers)
    smallest = smallest == 0.0 ? l.youngs_modulus_Pa : std::min(smallest, l.youngs_modulus_Pa);
  abs_tol_Pa_ = std::max(1e-12, 1e-6 * smallest);
}

void ViscoelasticTensorMass::add_forces(VectorRef x, VectorRef v, const double* q, MutableVectorRef f,
                                        double* qdot) const {
  const std::size_t terms = prony_.g.size();
  for (int t = 0; t < mesh_->tet_count(); ++t) {
    const std::size_t base = static_cast<std::size_t>(t) * terms * 6;
    if (removed_[static_cast<std::size_t>(t)]) {
      if (qdot) std::fill(qdot + base, qdot + base + 6 * terms, 0.0);
      continue;
    }
    const TetShape& shape = shape_[static_cast<std::size_t>(t)];
    const LameParameters& lame = lame_[static_cast<std::size_t>(t)];
    const Matrix34d xe = element_positions(x, t);
    const Matrix34d ve = element_positions(v, t);
    const Eigen::Matrix3d F = xe * shape.grad;
    const Eigen::Matrix3d Fdot = ve * shape.grad;
    const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
    const Eigen::Matrix3d Edot = 0.5 * (F.transpose() * Fdot + Fdot.transpose() * F);
    const Eigen::Matrix3d Se = stvk_stress(E, lame);
    const Eigen::Matrix3d Se_dot = stvk_stress(Edot, lame);  // linear in E
    Eigen::Matrix3d S = Se;
    for (std::size_t k = 0; k < terms; ++k) {
      const Eigen::Matrix3d Q = from_voigt(q + base + 6 * k);
      S += Q;
      if (qdot) to_voigt(prony_.g[k] * Se_dot - Q / prony_.tau_s[k], qdot + base + 6 * k);
    }
    const Matrix34d fe = forces_from_stress(shape, F, S);
    const Eigen::Vector4i& nodes = mesh_->tets[static_cast<std::size_t>(t)];
    for (int a = 0; a < 4; ++a) f.segment<3>(3 * nodes[a]) += fe.col(a);
  }
}

void ViscoelasticTensorMass::add_tangent(VectorRef x, double gamma, NodeBlockMatrix& K) const {
  double factor = 1.0;
  for (std::size_t k = 0; k < prony_.g.size(); ++k) factor += prony_.g[k] * prony_.tau_s[k] / (prony_.tau_s[k] + gamma);
  for (int t = 0; t < mesh_->tet_count(); ++t) {
    if (removed_[static_cast<std::size_t>(t)]) continue;
    const Matrix12d Ke = factor * stvk_tangent(shape_[static_cast<std::size_t>(t)], element_positions(x, t),
                                               lame_[static_cast<std::size_t>(t)]);
    const Eigen::Vector4i& v = mesh_->tets[static_cast<std::size_t>(t)];
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) K.add_block(v[a], v[b], Ke.block<3, 3>(3 * a, 3 * b));
  }
}

void ViscoelasticTensorMass::extra_state_decay_rates(std::vector<double>& rates) const {
  const std::size_t terms = prony_.g.size();
  rates.resize(static_cast<std::size_t>(extra_state_size()));
  for (std::size_t t = 0; t < mesh_->tets.size(); ++t)
    for (std::size_t k = 0; k < terms; ++k)
      for (int c = 0; c < 6; ++c) rates[(t * terms + k) * 6 + static_cast<std::size_t>(c)] = 1.0 / prony_.tau_s[k];
}

void ViscoelasticTensorMass::add_internal_variable_forces(VectorRef x, const double* r_q, double gamma,
                                                          MutableVectorRef f) const {
  const std::size_t terms = prony_.g.size();
  for (int t = 0; t < mesh_->tet_count(); ++t) {
    if (removed_[static_cast<std::size_t>(t)]) continue;
    const std::size_t base = static_cast<std::size_t>(t) * terms * 6;
    Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
    for (std::size_t k = 0; k < terms; ++k) S += from_voigt(r_q + base + 6 * k) / (1.0 + gamma / prony_.tau_s[k]);
    const TetShape& shape = shape_[static_cast<std::size_t>(t)];
    const Matrix34d fe = forces_from_stress(shape, element_positions(x, t) * shape.grad, S);
    const Eigen::Vector4i& nodes = mesh_->tets[static_cast<std::size_t>(t)];
    for (int a = 0; a < 4; ++a) f.segment<3>(3 * nodes[a]) += fe.col(a);
  }
}

void ViscoelasticTensorMass::internal_variable_correction(VectorRef x, VectorRef b, const double* r_q, double gamma,
                                                          double* z_q) const {
  const std::size_t terms = prony_.g.size();
  for (int t = 0; t < mesh_->tet_count(); ++t) {
    const std::size_t base = static_cast<std::size_t>(t) * terms * 6;
    if (removed_[static_cast<std::size_t>(t)]) {
      for (std::size_t i = 0; i < 6 * terms; ++i) z_q[base + i] = r_q[base + i];
      continue;
    }
    const TetShape& shape = shape_[static_cast<std::size_t>(t)];
    const Eigen::Matrix3d F = element_positions(x, t) * shape.grad;
    const Eigen::Matrix3d Fdot = element_positions(b, t) * shape.grad;
    const Eigen::Matrix3d Se_dot =
        stvk_stress(0.5 * (F.transpose() * Fdot + Fdot.transpose() * F), lame_[static_cast<std::size_t>(t)]);
    for (std::size_t k = 0; k < terms; ++k) {
      double h[6];
      to_voigt(prony_.g[k] * Se_dot, h);
      const double denominator = 1.0 + gamma / prony_.tau_s[k];
      for (int c = 0; c < 6; ++c) z_q[base + 6 * k + c] = (r_q[base + 6 * k + c] + gamma * h[c]) / denominator;
    }
  }
}

std::size_t ViscoelasticTensorMass::memory_bytes() const {
  return StvkTensorMass::memory_bytes() + static_cast<std::size_t>(extra_state_size()) * sizeof(double);
}

}  // namespace puncture::comparison
