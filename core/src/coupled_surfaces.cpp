#include "puncture/coupled_surfaces.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <stdexcept>
#include <tuple>

#include "puncture/surface_transmission.hpp"

namespace puncture {

namespace {

constexpr double kFirstLevel_m = 0.25e-3, kLevelRatio = 1.3;  // transmission ladder: 0.25 mm x 1.3^i

/// T on the grid for depth_m: the same grid and depth give the same matrix,
/// so it is computed once per process.
std::shared_ptr<const Eigen::MatrixXd> grid_weights(const std::vector<double>& grid, double depth_m) {
  static std::mutex mutex;
  static std::map<std::tuple<std::size_t, long long, long long>, std::shared_ptr<const Eigen::MatrixXd>> cache;
  const auto key = std::make_tuple(grid.size(), std::llround(grid[1] * 1e12), std::llround(depth_m * 1e12));
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (const auto it = cache.find(key); it != cache.end()) return it->second;
  }
  auto w = std::make_shared<const Eigen::MatrixXd>(transmission_weights(grid, grid, depth_m));
  std::lock_guard<std::mutex> lock(mutex);
  return cache.emplace(key, std::move(w)).first->second;
}

/// profile_value_at on the uniform grid, found in O(1) instead of by search
/// (every node of every layer, whenever the surfaces are read); 0 beyond it.
double on_grid(const std::vector<double>& grid, const Eigen::VectorXd& values, double r) {
  const double x = r / grid[1];
  const auto j = static_cast<Eigen::Index>(std::floor(x));
  if (j + 1 >= values.size()) return j + 1 == values.size() && x == static_cast<double>(j) ? values(j) : 0.0;
  const double t = x - static_cast<double>(j);
  return (1.0 - t) * values(j) + t * values(j + 1);
}

}  // namespace

SurfaceCoupling::SurfaceCoupling(const std::vector<LayerGeometry>& layers, double slab_depth_m)
    : n_(layers.size()),
      lattice_(n_, nullptr),
      node_radius_(n_),
      ring_radius_(n_),
      ring_count_(n_),
      weights_(n_, std::vector<std::shared_ptr<const Eigen::MatrixXd>>(n_)),
      baseline_(n_),
      break_profile_(n_),
      break_force_N_(n_, 0.0),
      break_depth_m_(n_, 0.0),
      has_baseline_(n_, false),
      has_break_(n_, false),
      profile_(n_) {
  double finest = 0.0, widest = 0.0;
  int most_rings = 1;
  for (std::size_t k = 0; k < n_; ++k) {
    const LayerGeometry& g = layers[k];
    lattice_[k] = g.lattice;
    if (!g.lattice) continue;
    if (!(g.spacing_m > 0.0) || !std::isfinite(g.spacing_m))
      throw std::invalid_argument("SurfaceCoupling: spacing must be > 0");
    const int nodes = g.lattice->node_count(), w = g.lattice->rings_w;
    most_rings = std::max(most_rings, w);
    node_radius_[k].resize(static_cast<std::size_t>(nodes));
    ring_radius_[k].assign(static_cast<std::size_t>(w), 0.0);
    ring_count_[k].assign(static_cast<std::size_t>(w), 0);
    for (int i = 0; i < nodes; ++i) {
      const double r = g.lattice->planar_position(i, g.spacing_m).norm();
      const auto ring = static_cast<std::size_t>(g.lattice->ring[static_cast<std::size_t>(i)] - 1);
      node_radius_[k][static_cast<std::size_t>(i)] = r;
      ring_radius_[k][ring] += r;
      ++ring_count_[k][ring];
    }
    for (int j = 0; j < w; ++j) ring_radius_[k][static_cast<std::size_t>(j)] /= ring_count_[k][static_cast<std::size_t>(j)];
    ring_radius_[k][0] = 0.0;
    finest = finest == 0.0 ? g.spacing_m : std::min(finest, g.spacing_m);
    widest = std::max(widest, ring_radius_[k].back());
  }
  if (finest == 0.0) return;  // no force meshes: nothing to draw
  const double dr = 0.5 * finest;
  const auto points = static_cast<std::size_t>(std::ceil(widest / dr)) + 1;
  grid_.resize(std::max<std::size_t>(points, 2));
  for (std::size_t g = 0; g < grid_.size(); ++g) grid_[g] = dr * static_cast<double>(g);
  for (std::size_t a = 0; a < n_; ++a) {
    profile_[a] = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(grid_.size()));
    baseline_[a] = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(grid_.size()));
    break_profile_[a] = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(grid_.size()));
    for (std::size_t k = a + 1; k < n_; ++k) {
      const double depth = layers[k].top_depth_m - layers[a].top_depth_m;
      if (!(depth > 0.0)) throw std::invalid_argument("SurfaceCoupling: layer tops must deepen downwards");
      if (lattice_[a] && lattice_[k]) weights_[a][k] = grid_weights(grid_, depth);
    }
  }
  ring_means_ = Eigen::VectorXd::Zero(most_rings);
  const auto g = static_cast<Eigen::Index>(grid_.size());
  scratch_ = carried_ = level_lo_ = level_hi_ = Eigen::VectorXd::Zero(g);
  for (double c = kFirstLevel_m;; c *= kLevelRatio) {
    ladder_.push_back(grid_weights(grid_, c));
    if (c >= slab_depth_m) break;
  }
}

void SurfaceCoupling::own_profile(std::size_t k, const Eigen::Ref<const Eigen::VectorXd>& own,
                                  Eigen::VectorXd& out) const {
  const std::vector<int>& ring = lattice_[k]->ring;
  const std::vector<double>& radius = ring_radius_[k];
  auto means = ring_means_.head(static_cast<Eigen::Index>(radius.size()));
  means.setZero();
  for (Eigen::Index i = 0; i < own.size(); ++i) means(ring[static_cast<std::size_t>(i)] - 1) += own(i);
  for (Eigen::Index j = 0; j < means.size(); ++j) means(j) /= ring_count_[k][static_cast<std::size_t>(j)];
  for (std::size_t g = 0; g < grid_.size(); ++g)
    out(static_cast<Eigen::Index>(g)) = profile_value_at(radius, means.data(), grid_[g]);
}

void SurfaceCoupling::add_faded_baseline(std::size_t k, Eigen::VectorXd& profile) const {
  if (!has_baseline_[k] || !(baseline_[k](0) > 0.0)) return;
  const double taken_over = std::clamp(profile(0) / baseline_[k](0), 0.0, 1.0);  // s of the header
  profile = profile.cwiseMax((1.0 - taken_over) * baseline_[k]);
}

void SurfaceCoupling::freeze_break(std::size_t k, const Eigen::Ref<const Eigen::VectorXd>& own_at_break, double force_N,
                                   double tip_depth_m) {
  if (k >= n_ || !lattice_[k]) return;
  Eigen::VectorXd& p = break_profile_[k];
  own_profile(k, own_at_break, p);
  add_faded_baseline(k, p);
  break_force_N_[k] = force_N;
  break_depth_m_[k] = tip_depth_m;
  has_break_[k] = true;
}

void SurfaceCoupling::set_break_force(std::size_t k, double force_N) {
  if (k < n_ && has_break_[k]) break_force_N_[k] = force_N;
}

bool SurfaceCoupling::baseline_taken_over(std::size_t k, const Eigen::Ref<const Eigen::VectorXd>& own_k) const {
  if (k >= n_ || !lattice_[k] || !has_baseline_[k] || !(baseline_[k](0) > 0.0)) return true;
  own_profile(k, own_k, scratch_);
  return scratch_(0) >= baseline_[k](0);
}

void SurfaceCoupling::freeze_baseline(std::size_t k) {
  if (k == 0 || k >= n_ || !lattice_[k] || !lattice_[k - 1] || !has_break_[k - 1]) return;
  baseline_[k].noalias() = *weights_[k - 1][k] * break_profile_[k - 1];
  has_baseline_[k] = true;
}

void SurfaceCoupling::transmitted(const Eigen::VectorXd& profile, double depth_m, Eigen::VectorXd& out) const {
  if (!(depth_m > 0.0) || ladder_.empty()) {
    out = profile;
    return;
  }
  if (depth_m < kFirstLevel_m) {
    const double t = depth_m / kFirstLevel_m;
    level_hi_.noalias() = *ladder_[0] * profile;
    out = (1.0 - t) * profile + t * level_hi_;
    return;
  }
  const double x = std::log(depth_m / kFirstLevel_m) / std::log(kLevelRatio);
  const auto i = std::min(static_cast<std::size_t>(std::floor(x)), ladder_.size() - 1);
  if (i + 1 >= ladder_.size()) {  // beyond the slab: the deepest level
    out.noalias() = *ladder_.back() * profile;
    return;
  }
  const double lo = kFirstLevel_m * std::pow(kLevelRatio, static_cast<double>(i)), hi = lo * kLevelRatio;
  const double t = (depth_m - lo) / (hi - lo);
  level_lo_.noalias() = *ladder_[i] * profile;
  level_hi_.noalias() = *ladder_[i + 1] * profile;
  out = (1.0 - t) * level_lo_ + t * level_hi_;
}

void SurfaceCoupling::drawn(const std::vector<Eigen::VectorXd>& own, std::size_t a, std::vector<Eigen::VectorXd>& d,
                            const LoadAfterBreak* load) const {
  for (std::size_t k = 0; k < n_; ++k)
    if (lattice_[k]) own_profile(k, own[k], profile_[k]);
  if (load && load->layer < n_ && lattice_[load->layer] && has_break_[load->layer] &&
      break_force_N_[load->layer] > 0.0) {
    const std::size_t k = load->layer;
    const double c = std::max(0.0, load->tip_depth_m - break_depth_m_[k]);
    transmitted(break_profile_[k], c, carried_);
    transmitted(break_profile_[k], 0.5 * c, scratch_);
    carried_ = (load->tip_force_N / break_force_N_[k]) * carried_ + (load->shaft_force_N / break_force_N_[k]) * scratch_;
    profile_[k] = profile_[k].cwiseMax(carried_);
  }
  if (a < n_ && lattice_[a]) {
    add_faded_baseline(a, profile_[a]);
    for (std::size_t k = a + 1; k < n_; ++k)
      if (lattice_[k]) {
        carried_.noalias() = *weights_[a][k] * profile_[a];
        profile_[k] = profile_[k].cwiseMax(carried_);
      }
  }
  for (std::size_t k = std::min(a, n_ - 1); k-- > 0;)  // broken layers rest on the layer below
    if (lattice_[k] && lattice_[k + 1]) profile_[k] = profile_[k].cwiseMax(profile_[k + 1]);
  for (std::size_t k = 0; k < n_; ++k) {
    if (!lattice_[k]) continue;
    d[k].resize(own[k].size());  // sized by the caller: no allocation
    for (Eigen::Index i = 0; i < own[k].size(); ++i)
      d[k](i) = std::max(own[k](i), on_grid(grid_, profile_[k], node_radius_[k][static_cast<std::size_t>(i)]));
  }
}

}  // namespace puncture
