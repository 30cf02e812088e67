// simulator_handle.cpp: see simulator_handle.hpp.
#include "simulator_handle.hpp"

#include <cmath>
#include <stdexcept>

namespace puncture::python {

SimulatorHandle::SimulatorHandle(const Scene& scene)
    : scene_(scene),
      model_(build_realtime_model(scene)),
      dt_(1.0 / scene.realtime.haptic_rate_Hz),
      insertion_direction_(insertion_direction(scene.insertion)) {
  for (const Layer& l : scene.layers) names_->push_back(l.name);
}

void SimulatorHandle::reset() {
  model_ = build_realtime_model(scene_);
  ticks_ = 0;
  last_time_s_ = 0.0;
  last_depth_m_ = 0.0;
}

std::size_t SimulatorHandle::layer_index(const std::string& name) const {
  for (std::size_t k = 0; k < names_->size(); ++k)
    if ((*names_)[k] == name) return k;
  throw std::out_of_range("no layer '" + name + "' in scene '" + scene_.name + "'");
}

TickRecord SimulatorHandle::step(const NeedleState& needle) {
  const std::size_t events_before = model_.simulator->puncture_events().size();
  TickRecord record;
  record.result = model_.simulator->tick(needle);
  record.direction = needle.direction;
  const auto& events = model_.simulator->puncture_events();
  for (std::size_t i = events_before; i < events.size(); ++i) record.events.emplace_back(events[i]);
  record.layer_names = names_;
  ++ticks_;
  last_time_s_ = needle.time_s;
  last_depth_m_ = needle.depth_m();
  return record;
}

TickRecord SimulatorHandle::tick_depth(double depth_m, std::optional<double> velocity_m_per_s,
                                       std::optional<double> time_s) {
  if (!std::isfinite(depth_m)) throw std::invalid_argument("tick: depth_mm must be finite");
  NeedleState needle;
  // On the scene's insertion line (needle.hpp): at depth_m below the skin plane.
  const Eigen::Vector3d& d = insertion_direction_;
  needle.direction = d;
  needle.tip_position_m = point_on_insertion_line(d, depth_m / -d.z());
  needle.time_s = time_s ? *time_s : (ticks_ == 0 ? 0.0 : last_time_s_ + dt_);
  // The depth's rate is vertical; the needle moves along its inclined axis, 1 / cos a as fast.
  needle.axial_velocity_m_per_s =
      velocity_m_per_s ? *velocity_m_per_s : (ticks_ == 0 ? 0.0 : (depth_m - last_depth_m_) / dt_ / -d.z());
  return step(needle);
}

TickRecord SimulatorHandle::tick_pose(const Eigen::Vector3d& tip_m, const Eigen::Vector3d& direction,
                                      double velocity_m_per_s, std::optional<double> time_s) {
  const double norm = direction.norm();
  if (!(norm > 0.0) || !std::isfinite(norm)) throw std::invalid_argument("tick_pose: direction must be a finite non-zero vector");
  NeedleState needle;
  needle.tip_position_m = tip_m;
  needle.direction = direction / norm;
  needle.axial_velocity_m_per_s = velocity_m_per_s;
  needle.time_s = time_s ? *time_s : (ticks_ == 0 ? 0.0 : last_time_s_ + dt_);
  return step(needle);
}

ScriptedRunResult SimulatorHandle::run(const ProgressCallback& on_progress) {
  if (ticks_ != 0)
    throw std::logic_error("run() starts from fresh tissue, and this simulator has ticked " + std::to_string(ticks_) +
                           " times: call reset() first");
  ScriptedRunResult result = run_scripted_insertion(model_, scene_, {}, on_progress);
  ticks_ = static_cast<long>(result.ticks.size());
  if (!result.ticks.empty()) {
    last_time_s_ = result.ticks.back().time_s;
    last_depth_m_ = result.ticks.back().depth_m;
  }
  return result;
}

}  // namespace puncture::python
