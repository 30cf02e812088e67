// bench_replay.hpp: replaying a scripted insertion tick by tick inside a
// Google Benchmark loop (shared by bench_tick.cpp and bench_effects.cpp).
//
// The haptic tick is stateful (force meshes, punctured layers, resumption),
// so a benchmark cannot call tick() with the same needle state again and
// again. Instead:
//   * InsertionScript samples the scene's ScriptedTrajectory at the haptic
//     step (tick i at t = i / haptic_rate_Hz, i = 0 .. duration) and finds
//     the phases of the insertion with one untimed dry run: the ticks in
//     which the skin is pressed before it breaks, the window right after the
//     skin breaks (skin resumption + fat pressing), the ticks after the last
//     puncture while the needle still moves in (damping of every punctured
//     layer + resumption), the ticks with contact (tip below the skin
//     surface: where the work is) and the whole trajectory.
//   * TickReplay owns a simulator and replays the ticks [begin, end) of one
//     phase; when it reaches `end`, restart() builds a fresh simulator (copies
//     of the already fitted SH layer surfaces, so no refit) and advances it
//     untimed through [0, begin). Benchmarks call restart() between
//     state.PauseTiming() and state.ResumeTiming(), so one benchmark
//     iteration is exactly one timed tick().
// Times: the benchmark reports time per iteration = per tick.
#pragma once

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "puncture/model/realtime_model.hpp"
#include "puncture/needle.hpp"
#include "puncture/scene.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/simulator.hpp"

namespace puncture::bench {

inline Scene default_scene() { return load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json"); }
/// The committed tuned preset (scripts/results_validation.sh): the model the app and the validations run.
inline Scene tuned_scene() {
  return load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/results/tuned_preset/default_tuned.json");
}

/// Tick range [begin, end) of the scripted trajectory.
struct TickRange {
  std::size_t begin = 0;
  std::size_t end = 0;
  std::size_t size() const { return end > begin ? end - begin : 0; }
};

/// The needle state of every haptic tick and the phases of one insertion.
struct InsertionScript {
  std::vector<NeedleState> needle;  ///< tick i at t = i dt, whole trajectory
  std::vector<std::size_t> puncture_ticks;  ///< tick of each puncture event, in order
  std::vector<double> puncture_depths_m;
  std::size_t insertion_end_tick = 0;  ///< first tick at or after the target depth is reached
  TickRange whole;             ///< every tick of the trajectory
  TickRange press_skin;        ///< skin Pressed (tip below its contact point), before it breaks
  TickRange after_skin_break;  ///< the ticks of the skin's recovery time after it broke
  TickRange inside_punctured;  ///< after the last puncture, until the target depth is reached
  TickRange in_tissue;         ///< ticks with contact: first to last tick with the tip below the skin surface
};

/// Copies of the fitted layer surfaces, ready to hand to a new simulator.
inline std::vector<std::unique_ptr<ContactSurface>> copy_surfaces(const RealtimeModel& model) {
  std::vector<std::unique_ptr<ContactSurface>> out;
  for (const LayerSurface* s : model.surfaces) out.push_back(std::make_unique<LayerSurface>(*s));
  return out;
}

/// Samples the trajectory and finds the phases by one dry run of `model`'s
/// surfaces under `scene` (a fresh simulator; `model` is not advanced).
inline InsertionScript make_script(const Scene& scene, const RealtimeModel& model) {
  InsertionScript script;
  const ScriptedTrajectory trajectory(scene.insertion);
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  const std::size_t n = static_cast<std::size_t>(std::ceil(trajectory.duration() / dt - 1e-9)) + 1;
  script.needle.reserve(n);
  for (std::size_t i = 0; i < n; ++i) script.needle.push_back(trajectory.sample(static_cast<double>(i) * dt));
  script.insertion_end_tick = static_cast<std::size_t>(std::ceil(trajectory.insertion_end_s() / dt - 1e-9));
  script.whole = {0, n};

  PunctureSimulator sim(scene, copy_surfaces(model));
  bool skin_pressed_seen = false;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t events_before = sim.puncture_events().size();
    const TickResult& r = sim.tick(script.needle[i]);
    if (r.depth_m > 0.0) {
      if (script.in_tissue.size() == 0) script.in_tissue.begin = i;
      script.in_tissue.end = i + 1;
    }
    if (!skin_pressed_seen && r.layers[0].state == LayerState::Pressed) {
      skin_pressed_seen = true;
      script.press_skin.begin = i;
    }
    for (std::size_t e = events_before; e < sim.puncture_events().size(); ++e) {
      script.puncture_ticks.push_back(i);
      script.puncture_depths_m.push_back(sim.puncture_events()[e].depth_m);
    }
  }
  if (!script.puncture_ticks.empty()) {
    const std::size_t skin_break = script.puncture_ticks.front();
    if (!skin_pressed_seen) script.press_skin.begin = skin_break;
    script.press_skin.end = skin_break;
    const std::size_t window = static_cast<std::size_t>(
        std::ceil(scene.layers[0].resumption_time_s * scene.realtime.haptic_rate_Hz - 1e-9));
    script.after_skin_break = {skin_break + 1, std::min(n, skin_break + 1 + window)};
    script.inside_punctured = {script.puncture_ticks.back() + 1, std::max(script.puncture_ticks.back() + 1,
                                                                          script.insertion_end_tick)};
  } else if (skin_pressed_seen) {
    // The skin never breaks: the pressing phase runs to the target depth.
    script.press_skin.end = script.insertion_end_tick;
  }
  return script;
}

/// Replays the ticks [range.begin, range.end) of a script over and over.
class TickReplay {
 public:
  TickReplay(const Scene& scene, const RealtimeModel& model, const InsertionScript& script, TickRange range)
      : scene_(scene), model_(model), script_(script), range_(range) {
    if (range_.size() == 0) throw std::invalid_argument("TickReplay: empty tick range");
    restart();
  }

  bool at_end() const { return next_ >= range_.end; }

  /// Fresh simulator advanced (untimed by the caller) to range.begin.
  void restart() {
    simulator_.reset();
    simulator_ = std::make_unique<PunctureSimulator>(scene_, copy_surfaces(model_));
    for (std::size_t i = 0; i < range_.begin; ++i) simulator_->tick(script_.needle[i]);
    next_ = range_.begin;
  }

  /// The timed operation: one haptic tick.
  const TickResult& tick() { return simulator_->tick(script_.needle[next_++]); }

  const PunctureSimulator& simulator() const { return *simulator_; }

 private:
  const Scene& scene_;
  const RealtimeModel& model_;
  const InsertionScript& script_;
  TickRange range_;
  std::unique_ptr<PunctureSimulator> simulator_;
  std::size_t next_ = 0;
};

/// Fixed iteration count of a replay benchmark: whole replays of the range,
/// about 20000 timed ticks but at least 3 and at most 200 replays. Fixed,
/// because the untimed restarts (a fresh simulator advanced to range.begin)
/// cost far more than the ticks they serve when the range is short or late:
/// Google Benchmark's own iteration search would spend minutes in them.
inline benchmark::IterationCount replay_iterations(TickRange range) {
  if (range.size() == 0) return 1;
  const std::size_t replays = std::clamp<std::size_t>((20000 + range.size() - 1) / range.size(), 3, 200);
  return static_cast<benchmark::IterationCount>(replays * range.size());
}

/// The benchmark loop: one iteration = one tick; restarts are untimed.
/// Adds counters: the phase length in ticks and the number of punctures in
/// the whole insertion (so the table says what the phase contained).
inline void run_replay(benchmark::State& state, const Scene& scene, const RealtimeModel& model,
                       const InsertionScript& script, TickRange range) {
  if (range.size() == 0) {
    state.SkipWithError("empty phase: the scene never reaches it");
    for (auto _ : state) {
    }
    return;
  }
  TickReplay replay(scene, model, script, range);
  double force_sum_N = 0.0;
  for (auto _ : state) {
    if (replay.at_end()) {
      state.PauseTiming();
      replay.restart();
      state.ResumeTiming();
    }
    const TickResult& r = replay.tick();
    force_sum_N += r.total_force_N;
    benchmark::DoNotOptimize(force_sum_N);
  }
  state.counters["phase_ticks"] = static_cast<double>(range.size());
  state.counters["punctures"] = static_cast<double>(script.puncture_ticks.size());
}

}  // namespace puncture::bench
