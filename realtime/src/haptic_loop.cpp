#include "puncture/realtime/haptic_loop.hpp"

#include <cmath>
#include <stdexcept>

#include "puncture/realtime/realtime_clock.hpp"
#include "puncture/realtime/replay.hpp"

namespace puncture::realtime {
namespace {

/// The recording of one model tick (recording.hpp): the NeedleState fed to
/// the model, the device's pose, the forces (N) and the tip depth (m).
TickRecord tick_record(std::int64_t n, double wall_time_s, bool fresh, std::uint32_t flags, const NeedleState& needle,
                       const DevicePose& pose, const TickOutputs& out, double depth_m) noexcept {
  TickRecord r;
  r.tick = static_cast<std::uint64_t>(n);
  r.flags = (fresh ? kRecFreshTissue : 0u) | ((flags & kOutMagnitudeClamped) ? kRecMagnitudeClamped : 0u) |
            ((flags & kOutRateClamped) ? kRecRateClamped : 0u) | ((flags & kOutNoPose) ? kRecNoPose : 0u);
  r.layer_states = out.layer_states;
  r.wall_time_s = wall_time_s;
  r.needle_time_s = needle.time_s;
  for (int i = 0; i < 3; ++i) {
    r.tip_m[i] = needle.tip_position_m[i];
    r.direction[i] = needle.direction[i];
    r.pose_position_m[i] = pose.position_m[i];
    r.force_raw_N[i] = out.force_raw_N[i];
    r.force_sent_N[i] = out.force_sent_N[i];
  }
  r.axial_velocity_m_per_s = needle.axial_velocity_m_per_s;
  r.pose_orientation_wxyz[0] = pose.orientation.w();
  r.pose_orientation_wxyz[1] = pose.orientation.x();
  r.pose_orientation_wxyz[2] = pose.orientation.y();
  r.pose_orientation_wxyz[3] = pose.orientation.z();
  r.tissue_force_N = out.tissue_force_N;
  r.depth_m = depth_m;
  return r;
}

}  // namespace

HapticLoop::HapticLoop(const Scene& scene, ModelSupplier& models, HapticDevice& device, ForceGuard guard,
                       HapticLoopOptions options, HapticLoopSinks sinks)
    : dt_(1.0 / scene.realtime.haptic_rate_Hz),
      models_(models),
      device_(device),
      guard_(guard),
      options_(options),
      sinks_(sinks),
      model_(models.initial()),
      needle_from_pose_(dt_, options.velocity_cutoff_Hz) {
  if (!model_ || !model_->simulator) throw std::invalid_argument("HapticLoop: no initial model");
  if (!(options_.snapshot_rate_Hz > 0.0)) throw std::invalid_argument("HapticLoop: snapshot rate must be positive");
  snapshot_every_ = std::max<std::int64_t>(1, std::llround(scene.realtime.haptic_rate_Hz / options_.snapshot_rate_Hz));
  held_needle_.tip_position_m = Eigen::Vector3d(0.0, 0.0, scene.insertion.start_height_m);
}

HapticLoop::~HapticLoop() {
  request_stop();
  if (thread_.joinable()) thread_.join();
}

void HapticLoop::start() {
  if (thread_.joinable()) throw std::logic_error("HapticLoop already started");
  thread_ = std::thread([this] { run_paced(); });
}

void HapticLoop::join() {
  if (thread_.joinable()) thread_.join();
}

bool HapticLoop::step(std::int64_t n, double wall_time_s) {
  const double t = static_cast<double>(n) * dt_;
  device_.read(n, t, input_);
  if (input_.status == DeviceInput::Status::End) return false;

  bool fresh = false;
  if (input_.fresh_tissue) {
    RealtimeModel* next = models_.try_exchange(model_);
    device_.fresh_tissue_result(next != nullptr);
    if (!next) {
      // No spare model yet: hold (no model tick, the guard untouched, last force again).
      ++counters_.held_ticks;
      ++counters_.ticks;
      last_output_.tick = n;
      last_output_.flags |= kOutHeld;
      device_.write(last_output_);
      return true;
    }
    model_ = next;
    fresh = true;
    ++generation_;
    ++counters_.fresh_tissues;
    needle_from_pose_.reset();
  }

  NeedleState needle;
  std::uint32_t flags = options_.stability_warning ? kOutStabilityWarning : 0u;
  if (input_.has_exact_needle) {
    needle = input_.needle;
  } else if (input_.status == DeviceInput::Status::Pose) {
    needle = needle_from_pose_.convert(input_.pose, t);
  } else {
    needle = held_needle_;
    needle.axial_velocity_m_per_s = 0.0;
    needle.time_s = t;
    flags |= kOutNoPose;
    ++counters_.no_pose_ticks;
  }
  held_needle_ = needle;

  unsigned guard_flags = 0;
  const TickOutputs out = compute_tick(*model_->simulator, needle, guard_, guard_flags);
  const TickResult& result = model_->simulator->last_result();
  if (guard_flags & kMagnitudeClamped) flags |= kOutMagnitudeClamped, ++counters_.magnitude_clamped;
  if (guard_flags & kRateClamped) flags |= kOutRateClamped, ++counters_.rate_clamped;

  last_output_.tick = n;
  last_output_.time_s = t;
  last_output_.force_N = out.force_sent_N;
  last_output_.tissue_force_N = out.tissue_force_N;
  last_output_.depth_m = result.depth_m;
  last_output_.layer_states = out.layer_states;
  last_output_.flags = flags;
  device_.write(last_output_);

  if (input_.has_expected) {
    ++counters_.replay_compared;
    if (!outputs_identical(out, input_.expected)) {
      if (counters_.replay_mismatches == 0) counters_.first_mismatch_tick = n;
      ++counters_.replay_mismatches;
    }
  }
  counters_.max_tissue_force_N = std::max(counters_.max_tissue_force_N, std::abs(out.tissue_force_N));
  counters_.max_sent_force_N = std::max(counters_.max_sent_force_N, out.force_sent_N.norm());

  if (sinks_.recorder &&
      !sinks_.recorder->push(tick_record(n, wall_time_s, fresh, flags, needle, input_.pose, out, result.depth_m)))
    ++counters_.records_dropped;
  publish(n, wall_time_s, result, out, flags);
  ++counters_.model_ticks;
  ++counters_.ticks;
  return true;
}

void HapticLoop::publish(std::int64_t n, double wall_time_s, const TickResult& result, const TickOutputs& out,
                         std::uint32_t flags) {
  const Eigen::Vector3d& dir = held_needle_.direction;
  if (sinks_.samples) {
    TickSample s;
    s.time_s = result.time_s;
    s.depth_m = result.depth_m;
    s.tissue_force_N = out.tissue_force_N;
    s.sent_axial_N = -out.force_sent_N.dot(dir);
    s.lateral_force_N = result.lateral_force_N;
    s.layer_states = out.layer_states;
    s.flags = flags;
    s.model_generation = generation_;
    if (!sinks_.samples->try_push(s)) ++counters_.samples_dropped;
  }
  auto fill = [&](ViewSnapshot& v) {
    v.tick = n;
    v.model_generation = generation_;
    v.wall_time_s = wall_time_s;
    v.needle = held_needle_;
    v.tissue_force_N = out.tissue_force_N;
    v.force_sent_N = out.force_sent_N;
    v.flags = flags;
    fill_snapshot(v, *model_->simulator, result);
  };
  if (sinks_.snapshots && (n - last_snapshot_tick_ >= snapshot_every_)) {
    fill(sinks_.snapshots->back());
    sinks_.snapshots->publish();
    last_snapshot_tick_ = n;
    ++counters_.snapshots;
  }
  if (sinks_.capture && !captured_ && options_.capture_at_s >= 0.0 && held_needle_.time_s >= options_.capture_at_s) {
    fill(sinks_.capture->back());
    sinks_.capture->publish();
    captured_ = true;
  }
}

void HapticLoop::run_paced() {
  scheduling_ = make_thread_realtime(options_.realtime_priority, options_.cpu);
  try {
    device_.start();
    const double t0 = monotonic_now_s();
    double deadline = t0;
    for (std::int64_t n = 0; !stop_.load(std::memory_order_acquire); ++n) {
      if (options_.max_ticks > 0 && n >= options_.max_ticks) break;
      if (n > 0) wait_until_s(deadline, options_.spin_margin_s);
      const double start = monotonic_now_s();
      const bool more = step(n, start - t0);
      const double end = monotonic_now_s();
      if (!more) break;  // the device ended the session: nothing was computed
      double next = deadline + dt_;
      stats_.add_tick(start, end, next);
      ticks_done_.store(n + 1, std::memory_order_relaxed);
      missed_live_.store(stats_.missed_deadlines, std::memory_order_relaxed);
      if (end > next + dt_) {
        const double lost = std::floor((end - next) / dt_);
        stats_.skipped_periods += static_cast<std::int64_t>(lost);
        next += lost * dt_;
      }
      deadline = next;
    }
  } catch (const std::exception& e) {
    error_ = e.what();
  }
  finished_.store(true, std::memory_order_release);
}

}  // namespace puncture::realtime
