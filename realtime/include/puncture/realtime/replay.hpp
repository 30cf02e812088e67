// replay.hpp: one model tick as the app computes it, the replay device, and
// an offline replay that checks a recording bit for bit.
//
// compute_tick(): the model tick plus what the app derives from it, shared by
// the haptic loop and the offline replay so both do exactly the same
// arithmetic: tissue force F (TickResult::total_force_N, > 0 resisting
// insertion, along the needle), force on the needle f_raw =
// TickResult::force_on_needle_N (N, scene frame: -F * direction along the
// surface normal, plus the part across the axis of an inclined needle),
// force to the device f_sent = ForceGuard::apply(f_raw), packed layer states.
//
// ReplayDevice feeds a recording's NeedleStates verbatim, asks for a fresh
// tissue where the recording had one, and hands the recorded outputs to the
// loop, which compares them bit for bit (a tick held while waiting for a fresh
// model is not compared and does not touch the model or the guard).
//
// replay_recording(): the same without threads or clocks: a model built from
// `scene` (normally the recording's own scene text), every record ticked in
// order, outputs compared bit for bit (memcmp of the doubles: 0.0 and -0.0
// differ). Returns counts and the first mismatch.
#pragma once

#include <cstdint>
#include <string>

#include "puncture/realtime/device.hpp"
#include "puncture/realtime/force_guard.hpp"
#include "puncture/realtime/recording.hpp"

namespace puncture::realtime {

TickOutputs compute_tick(PunctureSimulator& simulator, const NeedleState& needle, ForceGuard& guard,
                         unsigned& guard_flags);

/// Bitwise equality; on a difference `what` (if given) names the first differing field.
bool outputs_identical(const TickOutputs& a, const TickOutputs& b, const char** what = nullptr) noexcept;

class ReplayDevice final : public HapticDevice {
 public:
  explicit ReplayDevice(const Recording& recording);  ///< keeps a reference: the recording must outlive it
  std::string name() const override { return "replay"; }
  void read(std::int64_t tick, double time_s, DeviceInput& input) noexcept override;
  void fresh_tissue_result(bool done) noexcept override;
  void write(const ForceOutput&) noexcept override {}
  std::size_t position() const { return next_; }

 private:
  const Recording& recording_;
  std::size_t next_ = 0;
  bool waiting_fresh_ = false;
};

struct ReplayComparison {
  std::int64_t ticks = 0;
  std::int64_t mismatches = 0;
  std::int64_t first_mismatch_tick = -1;  ///< recorded tick index
  std::string first_mismatch_field;
  double max_abs_force_difference_N = 0.0;  ///< over tissue, raw and sent forces
  int fresh_tissues = 0;
};

ReplayComparison replay_recording(const Recording& recording, const Scene& scene);

}  // namespace puncture::realtime
