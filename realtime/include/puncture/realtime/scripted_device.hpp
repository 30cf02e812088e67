// scripted_device.hpp: the scene's scripted insertion as a device.
//
// Tick n of a cycle reads ScriptedTrajectory::sample(n T) (approach, insert at
// constant speed, dwell, withdraw: needle.hpp), with the exact axial velocity
// (so a single cycle feeds the model exactly what `puncture run` feeds it).
// With `repeat`, after the withdrawal and a rest of `rest_s` the device asks
// for a fresh tissue and starts the insertion again, so sessions of any length
// keep puncturing (the 60 s real-time measurement); without it the needle
// stays at its end position. Forces written to it are ignored.
#pragma once

#include "puncture/realtime/device.hpp"

namespace puncture::realtime {

class ScriptedDevice final : public HapticDevice {
 public:
  ScriptedDevice(const Insertion& insertion, double tick_period_s, bool repeat, double rest_s = 0.5);
  std::string name() const override { return "scripted"; }
  void read(std::int64_t tick, double time_s, DeviceInput& input) noexcept override;
  void fresh_tissue_result(bool done) noexcept override;
  void write(const ForceOutput&) noexcept override {}

  double cycle_duration_s() const { return trajectory_.duration() + rest_s_; }
  int cycles_started() const { return cycles_; }

 private:
  ScriptedTrajectory trajectory_;
  double dt_, rest_s_;
  bool repeat_;
  std::int64_t cycle_ticks_ = 0;  ///< ticks since the current cycle started
  bool waiting_ = false;
  int cycles_ = 1;
};

}  // namespace puncture::realtime
