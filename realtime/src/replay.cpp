#include "puncture/realtime/replay.hpp"

#include <cmath>
#include <cstring>

#include "puncture/model/realtime_model.hpp"

namespace puncture::realtime {

TickOutputs compute_tick(PunctureSimulator& simulator, const NeedleState& needle, ForceGuard& guard,
                         unsigned& guard_flags) {
  const TickResult& r = simulator.tick(needle);
  TickOutputs o;
  o.tissue_force_N = r.total_force_N;
  o.force_raw_N = r.force_on_needle_N;
  o.force_sent_N = guard.apply(o.force_raw_N, guard_flags);
  o.layer_states = pack_layer_states(r);
  return o;
}

bool outputs_identical(const TickOutputs& a, const TickOutputs& b, const char** what) noexcept {
  auto same = [](const void* x, const void* y, std::size_t n) { return std::memcmp(x, y, n) == 0; };
  const char* diff = nullptr;
  if (!same(&a.tissue_force_N, &b.tissue_force_N, sizeof(double)))
    diff = "tissue_force_N";
  else if (!same(a.force_raw_N.data(), b.force_raw_N.data(), 3 * sizeof(double)))
    diff = "force_raw_N";
  else if (!same(a.force_sent_N.data(), b.force_sent_N.data(), 3 * sizeof(double)))
    diff = "force_sent_N";
  else if (a.layer_states != b.layer_states)
    diff = "layer_states";
  if (what) *what = diff;
  return diff == nullptr;
}

ReplayDevice::ReplayDevice(const Recording& recording) : recording_(recording) {}

void ReplayDevice::read(std::int64_t, double, DeviceInput& input) noexcept {
  if (next_ >= recording_.records.size()) {
    input.status = DeviceInput::Status::End;
    input.fresh_tissue = false;
    input.has_exact_needle = input.has_expected = false;
    return;
  }
  const TickRecord& r = recording_.records[next_];
  input.status = (r.flags & kRecNoPose) ? DeviceInput::Status::NoPose : DeviceInput::Status::Pose;
  input.pose.position_m = Eigen::Vector3d(r.pose_position_m[0], r.pose_position_m[1], r.pose_position_m[2]);
  input.pose.orientation = Eigen::Quaterniond(r.pose_orientation_wxyz[0], r.pose_orientation_wxyz[1],
                                              r.pose_orientation_wxyz[2], r.pose_orientation_wxyz[3]);
  input.pose.has_velocity = false;
  input.has_exact_needle = true;
  input.needle = r.needle();
  input.has_expected = true;
  input.expected = r.outputs();
  waiting_fresh_ = (r.flags & kRecFreshTissue) != 0;
  input.fresh_tissue = waiting_fresh_;
  if (!waiting_fresh_) ++next_;
}

void ReplayDevice::fresh_tissue_result(bool done) noexcept {
  if (done && waiting_fresh_) {
    waiting_fresh_ = false;
    ++next_;
  }
}

ReplayComparison replay_recording(const Recording& recording, const Scene& scene) {
  ReplayComparison c;
  RealtimeModel model = build_realtime_model(scene);
  ForceGuard guard(scene.haptics, 1.0 / scene.realtime.haptic_rate_Hz);
  for (const TickRecord& r : recording.records) {
    if (r.flags & kRecFreshTissue) {
      model = build_realtime_model(scene);
      ++c.fresh_tissues;
    }
    unsigned flags = 0;
    const TickOutputs got = compute_tick(*model.simulator, r.needle(), guard, flags);
    const TickOutputs want = r.outputs();
    const char* what = nullptr;
    if (!outputs_identical(got, want, &what)) {
      if (c.mismatches == 0) {
        c.first_mismatch_tick = static_cast<std::int64_t>(r.tick);
        c.first_mismatch_field = what;
      }
      ++c.mismatches;
    }
    c.max_abs_force_difference_N = std::max({c.max_abs_force_difference_N, std::abs(got.tissue_force_N - want.tissue_force_N),
                                             (got.force_raw_N - want.force_raw_N).cwiseAbs().maxCoeff(),
                                             (got.force_sent_N - want.force_sent_N).cwiseAbs().maxCoeff()});
    ++c.ticks;
  }
  return c;
}

}  // namespace puncture::realtime
