#include "puncture/model/realtime_model.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <numeric>
#include <cmath>
#include <stdexcept>

#include "puncture/needle.hpp"

namespace puncture {

LayerDisc layer_disc(const Scene& scene, std::size_t layer) {
  const double top = -scene.layer_top_depth_m(layer);
  return {top, top - scene.layers.at(layer).thickness_m, 0.5 * scene.sample.diameter_m};
}

RealtimeModel build_realtime_model(const Scene& scene) {
  RealtimeModel model;
  std::vector<std::unique_ptr<ContactSurface>> surfaces;
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const LayerDisc disc = layer_disc(scene, k);
    auto surface = std::make_unique<LayerSurface>(
        LayerSurface::fit(disc.top_z_m, disc.bottom_z_m, disc.radius_m, scene.realtime.sh_degree));
    model.surfaces.push_back(surface.get());
    model.fits.push_back({scene.layers[k].name, surface->degree(), surface->fit_report(),
                          surface->top_face_max_error_m(), surface->top_face_rms_error_m(),
                          surface->whole_surface_rms_error_m()});
    surfaces.push_back(std::move(surface));
  }
  model.simulator = std::make_unique<PunctureSimulator>(scene, std::move(surfaces));
  return model;
}

std::vector<LayerFitErrorEntry> scene_fit_error_sweep(const Scene& scene, const std::vector<int>& degrees) {
  std::vector<LayerFitErrorEntry> out;
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const LayerDisc disc = layer_disc(scene, k);
    for (const LayerFitErrorRow& row : layer_fit_error_sweep(disc.top_z_m, disc.bottom_z_m, disc.radius_m, degrees))
      out.push_back({scene.layers[k].name, row});
  }
  return out;
}

bool tick_has_contact(const TickResult& tick) {
  if (tick.depth_m > 0.0) return true;
  for (const LayerTickResult& l : tick.layers)
    if (l.state == LayerState::Pressed) return true;
  return false;
}

TickCost tick_cost(const ScriptedRunResult& run) {
  TickCost c;
  c.ticks = run.tick_wall_time_s.size();
  std::vector<double> contact, all = run.tick_wall_time_s;
  for (std::size_t i = 0; i < run.tick_wall_time_s.size() && i < run.ticks.size(); ++i)
    if (tick_has_contact(run.ticks[i])) contact.push_back(run.tick_wall_time_s[i]);
  c.contact_ticks = contact.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  c.contact_mean_s = contact.empty() ? nan : std::accumulate(contact.begin(), contact.end(), 0.0) / contact.size();
  if (contact.empty()) {
    c.contact_p99_s = nan;
  } else {
    const std::size_t k = std::min(contact.size() - 1, static_cast<std::size_t>(0.99 * contact.size()));
    std::nth_element(contact.begin(), contact.begin() + static_cast<long>(k), contact.end());
    c.contact_p99_s = contact[k];
  }
  if (!all.empty()) {
    std::nth_element(all.begin(), all.begin() + static_cast<long>(all.size() / 2), all.end());
    c.all_median_s = all[all.size() / 2];
  }
  return c;
}

long scripted_tick_count(const Scene& scene) {
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  const double duration = ScriptedTrajectory(scene.insertion).duration();
  return static_cast<long>(std::ceil(duration / dt - 1e-9)) + 1;
}

ScriptedRunResult run_scripted_insertion(RealtimeModel& model, const Scene& scene, const FrameCallback& on_frame,
                                         const ProgressCallback& on_progress) {
  if (!model.simulator) throw std::invalid_argument("run_scripted_insertion: model has no simulator");
  ScriptedNeedleDevice device(scene.insertion);
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  const long n_ticks = scripted_tick_count(scene);
  const double frame_interval_s = 1.0 / scene.realtime.frame_rate_Hz;

  ScriptedRunResult run;
  run.time_step_s = dt;
  run.ticks.reserve(static_cast<std::size_t>(n_ticks));
  run.tick_wall_time_s.reserve(static_cast<std::size_t>(n_ticks));
  int next_frame = 0;
  long next_progress = 0;
  for (long i = 0; i < n_ticks; ++i) {
    const double t = static_cast<double>(i) * dt;
    const NeedleState needle = device.read(t);
    const auto start = std::chrono::steady_clock::now();
    const TickResult& result = model.simulator->tick(needle);
    const auto stop = std::chrono::steady_clock::now();
    run.tick_wall_time_s.push_back(std::chrono::duration<double>(stop - start).count());
    run.ticks.push_back(result);
    if (on_frame && t + 0.5 * dt >= next_frame * frame_interval_s) {
      on_frame(*model.simulator, result, next_frame);
      ++next_frame;
    }
    if (on_progress && i >= next_progress && i + 1 < n_ticks) {
      on_progress(static_cast<double>(i) / static_cast<double>(n_ticks));
      next_progress += std::max(1L, n_ticks / 10);
    }
  }
  if (on_progress) on_progress(1.0);
  run.events = model.simulator->puncture_events();
  return run;
}

}  // namespace puncture
