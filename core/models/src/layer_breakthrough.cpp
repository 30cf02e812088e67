// layer_breakthrough.cpp: the scene's breakthrough rule for a comparison
// model's layer; see layer_breakthrough.hpp.
#include "puncture/comparison/layer_breakthrough.hpp"

#include <algorithm>
#include <stdexcept>

#include "puncture/breakthrough_rate.hpp"

namespace puncture::comparison {

LayerBreakthroughRule::LayerBreakthroughRule(const Layer& layer, double prescribed_depth_m)
    : criterion_(layer.force_law.breakthrough),
      prescribed_depth_m_(prescribed_depth_m),
      rings_(layer.force_mesh) {}

LayerBreakthroughRule LayerBreakthroughRule::of(const Scene& scene, std::size_t layer) {
  const std::vector<double>& prescribed = scene.comparison.prescribed_puncture_depths_m;
  return LayerBreakthroughRule(scene.layers.at(layer), layer < prescribed.size() ? prescribed[layer] : 0.0);
}

void LayerBreakthroughRule::start(double depth_m, double time_s) {
  last_depth_m_ = start_depth_m_ = depth_m;
  last_time_s_ = start_time_s_ = time_s;
  last_force_N_ = 0.0;
  work_J_ = 0.0;
}

void LayerBreakthroughRule::advance(double depth_m, double force_N, double time_s) {
  if (depth_m > last_depth_m_) work_J_ += 0.5 * (force_N + last_force_N_) * (depth_m - last_depth_m_);
  last_depth_m_ = depth_m;
  last_force_N_ = force_N;
  last_time_s_ = time_s;
}

double LayerBreakthroughRule::rate_factor() const {
  return breakthrough_rate_factor(criterion_, mean_pressing_speed_m_per_s(start_depth_m_, start_time_s_, last_depth_m_,
                                                                          last_time_s_, criterion_.reference_speed_m_per_s));
}

bool LayerBreakthroughRule::broken(double force_N, const std::vector<double>& ring_deflection_m) const {
  if (prescribed_depth_m_ > 0.0) return last_depth_m_ >= prescribed_depth_m_;
  switch (criterion_.kind) {
    case BreakthroughCriterion::Kind::Rings:
      if (ring_deflection_m.size() != rings_.points_m().size())
        throw std::invalid_argument("LayerBreakthroughRule: the ring rule needs a deflection at every lattice point");
      return rings_.broken(ring_deflection_m);
    case BreakthroughCriterion::Kind::CriticalForce:
      return force_N >= criterion_.critical_force_N * rate_factor();
    case BreakthroughCriterion::Kind::CriticalEnergy:
      return work_J_ >= criterion_.critical_energy_J * rate_factor();
  }
  return false;
}

double LayerBreakthroughRule::load_at_break_N(double force_N) const {
  if (prescribed_depth_m_ > 0.0 || criterion_.kind != BreakthroughCriterion::Kind::CriticalForce) return force_N;
  return std::min(force_N, criterion_.critical_force_N * rate_factor());
}

}  // namespace puncture::comparison
