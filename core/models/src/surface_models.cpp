// surface_models.cpp: boundary-element and SH-only comparison models; see
// surface_models.hpp.
#include "puncture/comparison/surface_models.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>

#include "puncture/comparison/boussinesq.hpp"
#include "puncture/model/realtime_model.hpp"

namespace puncture::comparison {

namespace {
constexpr double kPi = 3.14159265358979323846;

}  // namespace

// ---------------------------------------------------------------------------- common

LinearSurfaceModel::LinearSurfaceModel(const Scene& scene) : scene_(&scene) {
  for (std::size_t k = 0; k < scene.layers.size(); ++k)
    layers_.push_back(LayerRuntime{scene.layer_top_depth_m(k), 0.0, LayerBreakthroughRule::of(scene, k), {},
                                   LayerState::Untouched, false, 0.0, 0.0});
}

void LinearSurfaceModel::finish_setup(const std::vector<double>& stiffness) {
  for (std::size_t k = 0; k < layers_.size(); ++k) {
    LayerRuntime& layer = layers_[k];
    layer.stiffness_N_per_m = stiffness[k];
    if (!(stiffness[k] > 0.0) || !std::isfinite(stiffness[k]))
      throw std::runtime_error(name() + ": non-positive stiffness for layer \"" + scene_->layers[k].name + "\"");
    std::map<double, double> by_radius;  // the lattice repeats every radius six times
    for (double r : layer.breakthrough.rings().point_radii_m()) {
      const double key = std::round(r * 1e12) / 1e12;
      auto it = by_radius.find(key);
      if (it == by_radius.end()) it = by_radius.emplace(key, unit_deflection(k, r)).first;
      layer.ring_unit_deflection.push_back(it->second);
    }
  }
}

double LinearSurfaceModel::step(const NeedleState& needle) {
  const double depth = needle.depth_m();
  if (!std::isfinite(depth)) throw std::invalid_argument(name() + ": non-finite needle state");
  while (active_ < layers_.size()) {
    LayerRuntime& layer = layers_[active_];
    if (!layer.contact_started) {
      const double contact = std::max(layer.top_depth_m, activation_depth_m_);
      if (depth < contact) return 0.0;
      layer.contact_started = true;
      layer.contact_depth_m = contact;
      layer.state = LayerState::Pressed;
      layer.breakthrough.start(contact, needle.time_s);
    }
    layer.indentation_m = std::max(0.0, depth - layer.contact_depth_m);
    const double force = layer.stiffness_N_per_m * layer.indentation_m;
    layer.breakthrough.advance(depth, force, needle.time_s);
    std::vector<double> deflection;
    if (layer.breakthrough.needs_deflection()) {
      deflection.resize(layer.ring_unit_deflection.size());
      for (std::size_t i = 0; i < deflection.size(); ++i)
        deflection[i] = layer.indentation_m * layer.ring_unit_deflection[i];
    }
    if (needle.axial_velocity_m_per_s < 0.0 || !layer.breakthrough.broken(force, deflection)) return force;
    layer.state = LayerState::Punctured;
    layer.break_force_N = layer.breakthrough.load_at_break_N(force);
    layer.indentation_m = 0.0;
    activation_depth_m_ = depth;
    ++active_;
  }
  return 0.0;
}

std::vector<double> LinearSurfaceModel::surface_deflection_m(std::size_t layer, const std::vector<double>& r_m) const {
  std::vector<double> out(r_m.size(), 0.0);
  const LayerRuntime& l = layers_.at(layer);
  if (l.state != LayerState::Pressed || l.indentation_m == 0.0) return out;
  for (std::size_t i = 0; i < r_m.size(); ++i) out[i] = l.indentation_m * unit_deflection(layer, r_m[i]);
  return out;
}

// ---------------------------------------------------------------------------- BEM

BoundaryElementModel::BoundaryElementModel(const Scene& scene, const BemSettings& settings)
    : LinearSurfaceModel(scene), settings_(settings) {
  if (settings.elements_in_contact < 2) throw std::invalid_argument("BoundaryElementModel: too few elements");
  const std::vector<LayerElasticity> elasticity = layer_elasticity(scene);
  const std::size_t n_layers = scene.layers.size();
  const double max_radius = 0.5 * scene.sample.diameter_m;
  for (std::size_t k = 0; k < n_layers; ++k) {
    std::vector<ElasticLayer> stack;
    for (std::size_t j = k; j < n_layers; ++j)
      stack.push_back({scene.layers[j].thickness_m, elasticity[j].youngs_modulus_Pa, elasticity[j].poisson_ratio});
    half_spaces_.emplace_back(stack, max_radius);
  }
  const double a = scene.needle.radius_m;
  const int n = settings.elements_in_contact;
  for (int j = 0; j <= n; ++j) edges_.push_back(a * std::sin(0.5 * kPi * j / n));
  edges_.back() = a;
  std::vector<double> collocation;
  for (int i = 0; i < n; ++i)
    collocation.push_back(0.5 * (edges_[static_cast<std::size_t>(i)] + edges_[static_cast<std::size_t>(i) + 1]));

  std::vector<double> stiffness(n_layers);
  for (std::size_t k = 0; k < n_layers; ++k) {
    const LayeredHalfSpace& hs = half_spaces_[k];
    const ElasticLayer& top = hs.layers().front();
    const std::size_t nodes = hs.quadrature_nodes();
    // Element spectra S (n x nodes) and J_0(k_q r_i) at the collocation radii
    // (n x nodes): the remainder part of G is J0 S^T.
    Eigen::MatrixXd spectra(n, static_cast<Eigen::Index>(nodes)), j0(n, static_cast<Eigen::Index>(nodes));
    std::vector<std::vector<double>> element_spectra;
    for (int j = 0; j < n; ++j) {
      element_spectra.push_back(
          hs.annulus_spectrum(edges_[static_cast<std::size_t>(j)], edges_[static_cast<std::size_t>(j) + 1]));
      for (std::size_t q = 0; q < nodes; ++q) spectra(j, static_cast<Eigen::Index>(q)) = element_spectra.back()[q];
    }
    for (int i = 0; i < n; ++i)
      for (std::size_t q = 0; q < nodes; ++q)
        j0(i, static_cast<Eigen::Index>(q)) =
            std::cyl_bessel_j(0.0, hs.wavenumbers_per_m()[q] * collocation[static_cast<std::size_t>(i)]);
    Eigen::MatrixXd G = j0 * spectra.transpose();
    for (int i = 0; i < n; ++i) {
      const double rc = collocation[static_cast<std::size_t>(i)];
      for (int j = 0; j < n; ++j) {
        G(i, j) += love_uniform_disc_uz_m(1.0, edges_[static_cast<std::size_t>(j) + 1], rc, top.youngs_modulus_Pa,
                                          top.poisson_ratio);
        if (j > 0)
          G(i, j) -= love_uniform_disc_uz_m(1.0, edges_[static_cast<std::size_t>(j)], rc, top.youngs_modulus_Pa,
                                            top.poisson_ratio);
      }
    }
    const Eigen::VectorXd p = G.partialPivLu().solve(Eigen::VectorXd::Ones(n));
    unit_pressure_.emplace_back(p.data(), p.data() + n);
    std::vector<double> spectrum(nodes, 0.0);
    double force = 0.0;
    for (int j = 0; j < n; ++j) {
      for (std::size_t q = 0; q < nodes; ++q) spectrum[q] += p[j] * element_spectra[static_cast<std::size_t>(j)][q];
      force += p[j] * kPi * (edges_[static_cast<std::size_t>(j) + 1] * edges_[static_cast<std::size_t>(j) + 1] -
                             edges_[static_cast<std::size_t>(j)] * edges_[static_cast<std::size_t>(j)]);
    }
    unit_spectrum_.push_back(spectrum);
    stiffness[k] = force;
  }
  finish_setup(stiffness);
}

double BoundaryElementModel::love_part(std::size_t layer, double r) const {
  const ElasticLayer& top = half_spaces_[layer].layers().front();
  const std::vector<double>& p = unit_pressure_[layer];
  double u = 0.0;
  for (std::size_t j = 0; j < p.size(); ++j) {
    double love = love_uniform_disc_uz_m(1.0, edges_[j + 1], r, top.youngs_modulus_Pa, top.poisson_ratio);
    if (j > 0) love -= love_uniform_disc_uz_m(1.0, edges_[j], r, top.youngs_modulus_Pa, top.poisson_ratio);
    u += p[j] * love;
  }
  return u;
}

double BoundaryElementModel::unit_deflection(std::size_t layer, double r) const {
  if (r <= scene_->needle.radius_m) return 1.0;
  return love_part(layer, r) + half_spaces_.at(layer).remainder_displacement(unit_spectrum_[layer], r);
}

std::string BoundaryElementModel::description() const {
  std::ostringstream s;
  s << "boundary elements: rigid flat tip on the layered half-space (Boussinesq/Love half-space plus the "
       "Burmister layers and fixed base below), "
    << settings_.elements_in_contact << " annular elements on the needle disc; quasi-static";
  return s.str();
}

ModelSize BoundaryElementModel::model_size() const {
  ModelSize s;
  const long n = settings_.elements_in_contact;
  s.dofs = n;  // pressure unknowns of the pressed layer
  s.nodes = n + 1;
  s.elements = n * static_cast<long>(layers_.size());
  s.memory_bytes = static_cast<std::size_t>(n * n + 3 * n) * sizeof(double) * layers_.size() +
                   layers_.size() * 64 * sizeof(double);
  return s;
}

// ---------------------------------------------------------------------------- SH only

double SphericalHarmonicModel::spectral_stiffness_N_per_m(int l, double E, double nu, double R) {
  return E * R * std::sqrt(static_cast<double>(l) * (l + 1)) / (2.0 * (1.0 - nu * nu));
}

SphericalHarmonicModel::SphericalHarmonicModel(const Scene& scene)
    : LinearSurfaceModel(scene), degree_(scene.realtime.sh_degree) {
  const std::vector<LayerElasticity> elasticity = layer_elasticity(scene);
  const double a = scene.needle.radius_m;
  std::vector<Eigen::Vector2d> points{{0.0, 0.0}};
  for (double radius : {0.5 * a, a})
    for (int i = 0; i < 6; ++i)
      points.emplace_back(radius * std::cos(kPi * i / 3.0), radius * std::sin(kPi * i / 3.0));
  std::vector<double> stiffness;
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const LayerDisc disc = layer_disc(scene, k);
    surfaces_.push_back(LayerSurface::fit(disc.top_z_m, disc.bottom_z_m, disc.radius_m, degree_));
    // Length scale of the parameterisation at the pole: rho(theta) / theta for small theta.
    const double theta = 1e-3;
    double rho = 0.0, z = 0.0;
    surfaces_.back().profile().profile(std::cos(theta), rho, z);
    length_scale_m_.push_back(rho / theta);
    std::vector<double> g(static_cast<std::size_t>(degree_) + 1, 0.0);
    for (int l = 1; l <= degree_; ++l)
      g[static_cast<std::size_t>(l)] =
          (2.0 * l + 1.0) / (4.0 * kPi * spectral_stiffness_N_per_m(l, elasticity[k].youngs_modulus_Pa,
                                                                       elasticity[k].poisson_ratio, length_scale_m_[k]));
    g_l_.push_back(g);
    // The needle disc is held flat at 13 points when the expansion resolves it
    // (pi R_s / (l + 1/2) < a); otherwise only at its centre: a degree that
    // cannot resolve the disc cannot hold it flat either.
    std::vector<Eigen::Vector3d> directions;
    const bool resolves_disc = kPi * length_scale_m_[k] / (degree_ + 0.5) < a;
    for (std::size_t i = 0; i < (resolves_disc ? points.size() : 1); ++i)
      directions.push_back(direction_at(k, points[i].x(), points[i].y()));
    collocation_.push_back(directions);
    const int n = static_cast<int>(directions.size());
    Eigen::MatrixXd G(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) G(i, j) = green_m_per_N(k, directions[static_cast<std::size_t>(i)].dot(directions[static_cast<std::size_t>(j)]));
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(G);
    cod.setThreshold(1e-10);
    unit_forces_.push_back(cod.solve(Eigen::VectorXd::Ones(n)));
    stiffness.push_back(unit_forces_.back().sum());
  }
  finish_setup(stiffness);
}

Eigen::Vector3d SphericalHarmonicModel::direction_at(std::size_t layer, double x, double y) const {
  const double limit = 0.98 * 0.5 * scene_->sample.diameter_m;
  const double r = std::hypot(x, y);
  if (r > limit) {
    x *= limit / r;
    y *= limit / r;
  }
  if (r == 0.0) return Eigen::Vector3d::UnitZ();
  return surfaces_.at(layer).top_face_parameter(x, y).normalized();
}

double SphericalHarmonicModel::green_m_per_N(std::size_t layer, double c) const {
  c = std::clamp(c, -1.0, 1.0);
  const std::vector<double>& g = g_l_.at(layer);
  double p_prev = 1.0, p = c, sum = 0.0;  // P_0, P_1
  for (int l = 1; l <= degree_; ++l) {
    sum += g[static_cast<std::size_t>(l)] * p;
    const double next = ((2.0 * l + 1.0) * c * p - l * p_prev) / (l + 1.0);
    p_prev = p;
    p = next;
  }
  return sum;
}

double SphericalHarmonicModel::unit_deflection(std::size_t layer, double r) const {
  if (r <= scene_->needle.radius_m) return 1.0;
  const Eigen::Vector3d u = direction_at(layer, r, 0.0);
  const std::vector<Eigen::Vector3d>& points = collocation_.at(layer);
  double value = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) value += unit_forces_[layer][static_cast<Eigen::Index>(i)] * green_m_per_N(layer, points[i].dot(u));
  return value;
}

std::string SphericalHarmonicModel::description() const {
  std::ostringstream s;
  s << "SH only: layer surfaces of degree l = " << degree_
    << " deformed through their SH coefficients (half-space spectral stiffness), no force mesh; quasi-static";
  return s.str();
}

ModelSize SphericalHarmonicModel::model_size() const {
  ModelSize s;
  const long coefficients = static_cast<long>(degree_ + 1) * (degree_ + 1);
  s.dofs = coefficients;  // the deformation's SH coefficients of the pressed layer
  s.nodes = coefficients * static_cast<long>(layers_.size());
  s.elements = 0;
  // Per layer: the surface's three coordinate expansions, the deformation
  // coefficients, g_l and the collocation data.
  s.memory_bytes = layers_.size() * (static_cast<std::size_t>(4 * coefficients + degree_ + 1 + 13 * 4) * sizeof(double));
  return s;
}

}  // namespace puncture::comparison
