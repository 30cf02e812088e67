// haptic_loop.hpp: the 1 kHz haptic loop on its own thread.
//
// Every period T = 1 / rate the loop: reads the device; if the device asks for
// a fresh tissue, swaps in a spare model from the ModelSupplier (or, if none
// is ready, holds this tick: no model tick, the last force re-sent); turns the
// pose into a NeedleState (NeedleFromPose; a replay gives it verbatim; with no
// pose the needle is held with zero velocity); ticks the model and guards the
// force (compute_tick); writes the force to the device; compares it with the
// recording when replaying; pushes a TickRecord to the recorder and a
// TickSample to the view's ring; every 1 / snapshot_rate publishes a
// ViewSnapshot (and once, at the needle time capture_at_s, a snapshot to the
// capture buffer, so a screenshot shows that moment however slow the view is). Nothing in this path allocates, locks or waits for the renderer
// (tested: tests/realtime/test_haptic_loop.cpp).
//
// Pacing: tick n is scheduled at t0 + n T (steady clock); the thread sleeps
// until spin_margin before that and spins the rest (realtime_clock.hpp). A
// tick that ends after the next tick's scheduled start is a missed deadline;
// the next tick then starts at once. If the loop falls more than a whole
// period behind, the lost periods are skipped (counted) instead of run in a
// burst. Model time is n T for loop tick n.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

#include "puncture/realtime/device.hpp"
#include "puncture/realtime/force_guard.hpp"
#include "puncture/realtime/loop_statistics.hpp"
#include "puncture/realtime/model_supplier.hpp"
#include "puncture/realtime/recording.hpp"
#include "puncture/realtime/spsc_ring.hpp"
#include "puncture/realtime/triple_buffer.hpp"
#include "puncture/realtime/view_snapshot.hpp"

namespace puncture::realtime {

struct HapticLoopOptions {
  std::int64_t max_ticks = 0;        ///< stop after this many ticks (0: until request_stop() or the device ends)
  double spin_margin_s = 100e-6;     ///< sleep until this long before each deadline, then spin
  int realtime_priority = 80;        ///< SCHED_FIFO priority (0: normal scheduling)
  int cpu = -1;                      ///< pin the haptic thread to this CPU (-1: no pinning)
  double snapshot_rate_Hz = 120.0;   ///< view snapshots per second
  double velocity_cutoff_Hz = 100.0; ///< low-pass of differentiated device positions
  bool stability_warning = false;    ///< sets kOutStabilityWarning in every output
  double capture_at_s = -1.0;        ///< publish one snapshot to HapticLoopSinks::capture at this needle time (< 0: never)
};

struct HapticLoopSinks {
  RecordingWriter* recorder = nullptr;
  TripleBuffer<ViewSnapshot>* snapshots = nullptr;  ///< sized with init_snapshot()
  SpscRing<TickSample>* samples = nullptr;
  TripleBuffer<ViewSnapshot>* capture = nullptr;    ///< the state at options.capture_at_s (for a screenshot)
};

struct HapticLoopCounters {
  std::int64_t ticks = 0;            ///< loop ticks (model ticks + held ticks)
  std::int64_t model_ticks = 0;
  std::int64_t held_ticks = 0;       ///< waiting for a fresh model
  std::int64_t no_pose_ticks = 0;
  std::int64_t fresh_tissues = 0;
  std::int64_t magnitude_clamped = 0;
  std::int64_t rate_clamped = 0;
  std::int64_t samples_dropped = 0;  ///< view ring full
  std::int64_t records_dropped = 0;  ///< recorder ring full
  std::int64_t snapshots = 0;
  std::int64_t replay_compared = 0;
  std::int64_t replay_mismatches = 0;
  std::int64_t first_mismatch_tick = -1;
  double max_tissue_force_N = 0.0;
  double max_sent_force_N = 0.0;
};

class HapticLoop {
 public:
  HapticLoop(const Scene& scene, ModelSupplier& models, HapticDevice& device, ForceGuard guard,
             HapticLoopOptions options, HapticLoopSinks sinks);
  ~HapticLoop();  ///< stops and joins the thread
  HapticLoop(const HapticLoop&) = delete;
  HapticLoop& operator=(const HapticLoop&) = delete;

  void start();                    ///< runs run_paced() on a new thread
  void request_stop() noexcept { stop_.store(true, std::memory_order_release); }
  void join();
  bool finished() const noexcept { return finished_.load(std::memory_order_acquire); }
  /// Ticks done and deadlines missed so far (any thread, while running).
  std::int64_t ticks_done() const noexcept { return ticks_done_.load(std::memory_order_relaxed); }
  std::int64_t missed_so_far() const noexcept { return missed_live_.load(std::memory_order_relaxed); }

  /// The paced loop (what the thread runs).
  void run_paced();
  /// One tick without pacing; false when the device ended the session. Throws
  /// what the model throws (non-finite state).
  bool step(std::int64_t n, double wall_time_s);

  // --- after join() ---
  const LoopStatistics& statistics() const { return stats_; }
  const HapticLoopCounters& counters() const { return counters_; }
  const std::string& scheduling() const { return scheduling_; }
  const std::string& error() const { return error_; }  ///< exception that stopped the loop, if any

 private:
  void publish(std::int64_t n, double wall_time_s, const TickResult& result, const TickOutputs& out,
               std::uint32_t flags);

  double dt_;
  ModelSupplier& models_;
  HapticDevice& device_;
  ForceGuard guard_;
  HapticLoopOptions options_;
  HapticLoopSinks sinks_;
  RealtimeModel* model_;
  NeedleFromPose needle_from_pose_;
  NeedleState held_needle_;
  DeviceInput input_;
  ForceOutput last_output_;
  std::uint64_t generation_ = 0;
  std::int64_t snapshot_every_ = 1;
  std::int64_t last_snapshot_tick_ = -1000000;
  bool captured_ = false;
  LoopStatistics stats_;
  HapticLoopCounters counters_;
  std::string scheduling_, error_;
  std::atomic<bool> stop_{false}, finished_{false};
  std::atomic<std::int64_t> ticks_done_{0}, missed_live_{0};
  std::thread thread_;
};

}  // namespace puncture::realtime
