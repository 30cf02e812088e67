// realtime_model.hpp: the real-time SHF + MSM model assembled from a scene,
// and a scripted insertion run of it.
//
// build_realtime_model(scene):
//   In:  a validated Scene (SI units).
//   Out: per layer an SH LayerSurface fitted at scene.realtime.sh_degree to the
//        layer's disc (radius = sample diameter / 2, top at -layer_top_depth,
//        bottom at -(top depth + thickness)), with its fit report, and the
//        PunctureSimulator that owns the surfaces.
// run_scripted_insertion(model, scene, ...):
//   Drives the simulator tick by tick (dt = 1 / haptic_rate_Hz) along the
//   scene's scripted trajectory, from t = 0 to the end of the withdrawal.
//   Out: one TickResult per tick, the puncture events, the measured wall time
//   per tick. Calls on_frame at the visual frame rate (frame 0 at t = 0) and
//   on_progress with the fraction done (0..1) about every 10 %.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "puncture/scene.hpp"
#include "puncture/sh/layer_surface.hpp"
#include "puncture/simulator.hpp"

namespace puncture {

struct LayerSurfaceFitInfo {
  std::string layer;
  int degree = 0;
  SHFitReport report;
  double top_face_max_error_m = 0.0;
  double top_face_rms_error_m = 0.0;
  double whole_surface_rms_error_m = 0.0;
};

struct RealtimeModel {
  std::unique_ptr<PunctureSimulator> simulator;
  std::vector<const LayerSurface*> surfaces;  ///< owned by the simulator, top to bottom
  std::vector<LayerSurfaceFitInfo> fits;      ///< one per layer
};

/// The layer's disc geometry in the scene frame (m).
struct LayerDisc {
  double top_z_m;
  double bottom_z_m;
  double radius_m;
};
LayerDisc layer_disc(const Scene& scene, std::size_t layer);

RealtimeModel build_realtime_model(const Scene& scene);

/// Fit error of every layer's SH surface for each degree: the "SH degree l"
/// accuracy knob. One row per (layer, degree).
struct LayerFitErrorEntry {
  std::string layer;
  LayerFitErrorRow row;
};
std::vector<LayerFitErrorEntry> scene_fit_error_sweep(const Scene& scene, const std::vector<int>& degrees);

struct ScriptedRunResult {
  std::vector<TickResult> ticks;
  std::vector<PunctureEvent> events;
  double time_step_s = 0.0;
  std::vector<double> tick_wall_time_s;  ///< measured wall time of each tick() call
};

/// What one haptic tick costs where the work is: wall times (s) of the ticks
/// with contact (the tip below the undeformed skin surface, or a layer
/// pressed), mean and 99th percentile, beside the median over all ticks
/// (which, for a scripted run, is a tick without contact).
struct TickCost {
  std::size_t ticks = 0;
  std::size_t contact_ticks = 0;
  double contact_mean_s = 0.0;   ///< NaN without contact ticks
  double contact_p99_s = 0.0;    ///< NaN without contact ticks
  double all_median_s = 0.0;
};
bool tick_has_contact(const TickResult& tick);
TickCost tick_cost(const ScriptedRunResult& run);

using FrameCallback = std::function<void(const PunctureSimulator&, const TickResult&, int frame_index)>;
using ProgressCallback = std::function<void(double fraction_done)>;

/// Ticks of the scene's scripted run: t = 0, dt, ... up to the end of the trajectory.
long scripted_tick_count(const Scene& scene);

ScriptedRunResult run_scripted_insertion(RealtimeModel& model, const Scene& scene,
                                         const FrameCallback& on_frame = {},
                                         const ProgressCallback& on_progress = {});

}  // namespace puncture
