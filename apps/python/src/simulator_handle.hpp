// simulator_handle.hpp: what a puncture.Simulator holds: the scene, the
// real-time model built from it, and the needle's last state (for the
// defaults of tick(): the next time and the velocity from the depth change).
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "puncture/model/realtime_model.hpp"
#include "puncture/scene.hpp"
#include "tick_types.hpp"

namespace puncture::python {

class SimulatorHandle {
 public:
  explicit SimulatorHandle(const Scene& scene);

  /// One haptic tick with the needle on the insertion axis at depth_m below
  /// the skin surface. Defaults: time = last + dt (0 first), velocity =
  /// depth change / dt (0 first).
  TickRecord tick_depth(double depth_m, std::optional<double> velocity_m_per_s, std::optional<double> time_s);
  /// One haptic tick with the tip at `tip_m` (scene frame) moving along `direction`.
  TickRecord tick_pose(const Eigen::Vector3d& tip_m, const Eigen::Vector3d& direction, double velocity_m_per_s,
                       std::optional<double> time_s);
  /// The scene's scripted insertion from fresh tissue (throws if ticked).
  ScriptedRunResult run(const ProgressCallback& on_progress);
  /// Fresh tissue: the model rebuilt from the scene.
  void reset();

  const Scene& scene() const { return scene_; }
  const PunctureSimulator& simulator() const { return *model_.simulator; }
  const RealtimeModel& model() const { return model_; }
  double time_step_s() const { return dt_; }
  long ticks() const { return ticks_; }
  std::size_t layer_index(const std::string& name) const;
  const std::vector<std::string>& layer_names() const { return *names_; }

 private:
  TickRecord step(const NeedleState& needle);

  Scene scene_;
  RealtimeModel model_;
  std::shared_ptr<std::vector<std::string>> names_ = std::make_shared<std::vector<std::string>>();
  double dt_ = 0.0;
  Eigen::Vector3d insertion_direction_ = -Eigen::Vector3d::UnitZ();  ///< the scene's insertion line (needle.hpp)
  long ticks_ = 0;
  double last_time_s_ = 0.0;
  double last_depth_m_ = 0.0;
};

}  // namespace puncture::python
