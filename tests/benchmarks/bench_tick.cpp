// bench_tick.cpp: cost of one haptic tick of the real-time model: the tuned
// preset (results/tuned_preset/default_tuned.json: the model a user runs,
// whose skin and muscle force meshes stiffen, so every tick that presses them
// solves their step by Newton's method) and the default scene (every effect
// on, SH degree l = 16 unless a family varies it).
//
// Families (time per iteration = per tick; see bench_replay.hpp for how the
// stateful tick is replayed):
//   BM_tick_phase/tuned/<phase>, BM_tick_phase/<phase>   tuned preset,
//       default scene; phases press_skin, after_skin_break,
//       inside_punctured, in_tissue (every tick with the tip below the skin
//       surface: the ticks with contact), whole_insertion
//   BM_tick_integrator/<name>/<phase>   force-mesh integrator quasi_static,
//       explicit, implicit (the default) for press_skin and whole_insertion
//   BM_tick_rings_w/<w>/<phase>         every layer's w set to 2..32; L scaled
//       down where needed so (w - 1) L <= 0.9 R (sample radius R)
//   BM_tick_sh_degree/<l>/<phase>       SH degree of the layer surfaces
//   BM_sh_intersect_ray/<l>/<on_axis|off_axis>  LayerSurface::intersect_ray
//       alone (the only SH query inside the tick, once per layer when it is
//       first reached)
//   BM_tick_angle/<deg>/<phase>         tuned preset with the needle at 0, 15
//       and 30 deg to the surface normal (press_skin, in_tissue, whole_insertion)
//   BM_tick_distribution/tuned/whole_insertion, BM_tick_distribution/whole_insertion,
//   BM_tick_distribution/tuned_30deg/whole_insertion
//       one iteration = one whole insertion with every tick timed by
//       steady_clock (~20 ns overhead per tick); counters: percentiles of
//       the single-tick wall time (us) over all ticks, over the press_skin
//       ticks and over the ticks with contact (mean, p99 and max there: where
//       the work is; the haptic loop cares about the slow ticks, which a mean
//       per phase hides), and the worst tick with contact by its fastest time
//       over the insertions (its own cost, without preemption)
//   BM_force_mesh_relayout/<layer>      ForceMesh::relayout on the layer's SH
//       surface (l = 16) at an off-axis point (tangent-plane layout): the
//       extra work of the tick in which an off-axis needle first touches it
//   BM_force_mesh_refine/<layer>        the projection of kLayoutNodesPerTick
//       nodes onto the SH surface: the extra work of each of the following
//       ticks until the mesh lies on the surface
//   BM_build_realtime_model/<l>         SH fit + simulator construction
//       (outside the haptic loop; ms)
// Run through scripts/benchmarks.sh, which writes results/benchmarks/.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench_replay.hpp"

namespace puncture::bench {
namespace {

/// A scene, its model (fitted surfaces) and its insertion script, built once
/// per configuration and shared by every benchmark run of that configuration.
struct Setup {
  Scene scene;
  RealtimeModel model;
  InsertionScript script;
};

const Setup& setup_for(const std::string& key, const Scene& scene) {
  static std::map<std::string, std::unique_ptr<Setup>> cache;
  auto it = cache.find(key);
  if (it == cache.end()) {
    validate_scene(scene, "bench_tick:" + key);
    auto s = std::make_unique<Setup>();
    s->scene = scene;
    s->model = build_realtime_model(s->scene);
    s->script = make_script(s->scene, s->model);
    it = cache.emplace(key, std::move(s)).first;
  }
  return *it->second;
}

TickRange phase_range(const InsertionScript& script, const std::string& phase) {
  if (phase == "press_skin") return script.press_skin;
  if (phase == "after_skin_break") return script.after_skin_break;
  if (phase == "inside_punctured") return script.inside_punctured;
  if (phase == "in_tissue") return script.in_tissue;
  if (phase == "whole_insertion") return script.whole;
  throw std::invalid_argument("unknown phase " + phase);
}

/// Registers a replay of `phase` of the configuration `key` (built now, so
/// the iteration count can follow the phase length).
void register_phase(const std::string& name, const std::string& key, const Scene& scene, const std::string& phase,
                    bool count_nodes = false) {
  const Setup& s = setup_for(key, scene);
  const TickRange range = phase_range(s.script, phase);
  benchmark::RegisterBenchmark(name.c_str(), [&s, range, count_nodes](benchmark::State& st) {
    run_replay(st, s.scene, s.model, s.script, range);
    if (count_nodes) {
      int nodes = 0;
      for (std::size_t k = 0; k < s.model.simulator->layer_count(); ++k)
        nodes += s.model.simulator->force_mesh(k)->node_count();
      st.counters["mesh_nodes_all_layers"] = nodes;
    }
  })->Iterations(replay_iterations(range));
}

/// Every layer gets w rings; L shrinks where needed so the mesh stays inside
/// 0.9 of the sample radius.
Scene scene_with_rings(int w) {
  Scene scene = default_scene();
  const double radius_m = 0.5 * scene.sample.diameter_m;
  for (Layer& layer : scene.layers) {
    layer.force_mesh.rings_w = w;
    if (w > 1)
      layer.force_mesh.spacing_L_m = std::min(layer.force_mesh.spacing_L_m, 0.9 * radius_m / (w - 1));
  }
  return scene;
}

Scene scene_with_degree(int l) {
  Scene scene = default_scene();
  scene.realtime.sh_degree = l;
  return scene;
}

Scene scene_with_integrator(const std::string& name) {
  Scene scene = default_scene();
  scene.realtime.integrator = name;
  return scene;
}

/// Percentile q of v (reorders v); 0 for an empty v.
double percentile(std::vector<double>& v, double q) {
  if (v.empty()) return 0.0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

double max_of(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); }

/// Every tick of whole insertions timed one by one (see the header): the
/// percentiles over all ticks, the press_skin ticks and the ticks with
/// contact; worst_tick: the largest over the ticks of a tick's fastest time
/// over the insertions (a tick's own cost without the preemptions of a shared
/// machine, which the max includes).
void register_distribution(const std::string& name, const std::string& key, const Scene& scene) {
  const Setup& s = setup_for(key, scene);
  benchmark::RegisterBenchmark(name.c_str(), [&s](benchmark::State& st) {
    const TickRange press = s.script.press_skin;
    const TickRange contact = s.script.in_tissue;
    const std::size_t n = s.script.needle.size();
    std::vector<double> all_us, press_us, contact_us, fastest_us(n, 1e300);
    all_us.reserve(64 * n);
    press_us.reserve(64 * press.size());
    contact_us.reserve(64 * contact.size());
    for (auto _ : st) {
      st.PauseTiming();
      PunctureSimulator sim(s.scene, copy_surfaces(s.model));
      st.ResumeTiming();
      for (std::size_t i = 0; i < n; ++i) {
        const auto start = std::chrono::steady_clock::now();
        const TickResult& r = sim.tick(s.script.needle[i]);
        const auto stop = std::chrono::steady_clock::now();
        benchmark::DoNotOptimize(r.total_force_N);
        const double us = std::chrono::duration<double, std::micro>(stop - start).count();
        all_us.push_back(us);
        fastest_us[i] = std::min(fastest_us[i], us);
        if (i >= press.begin && i < press.end) press_us.push_back(us);
        if (i >= contact.begin && i < contact.end) contact_us.push_back(us);
      }
    }
    double contact_sum = 0.0;
    for (double us : contact_us) contact_sum += us;
    st.counters["contact_mean_us"] = contact_us.empty() ? 0.0 : contact_sum / static_cast<double>(contact_us.size());
    st.counters["max_us"] = max_of(all_us);
    st.counters["press_max_us"] = max_of(press_us);
    st.counters["contact_max_us"] = max_of(contact_us);
    const std::vector<double> contact_fastest(fastest_us.begin() + static_cast<std::ptrdiff_t>(contact.begin),
                                              fastest_us.begin() + static_cast<std::ptrdiff_t>(contact.end));
    st.counters["contact_worst_tick_us"] = max_of(contact_fastest);
    st.counters["p50_us"] = percentile(all_us, 0.50);
    st.counters["p90_us"] = percentile(all_us, 0.90);
    st.counters["p99_us"] = percentile(all_us, 0.99);
    st.counters["press_p50_us"] = percentile(press_us, 0.50);
    st.counters["press_p99_us"] = percentile(press_us, 0.99);
    st.counters["ticks_per_insertion"] = static_cast<double>(n);
    st.counters["contact_p50_us"] = percentile(contact_us, 0.50);
    st.counters["contact_p99_us"] = percentile(contact_us, 0.99);
    st.counters["contact_ticks"] = static_cast<double>(contact.size());
  })->Unit(benchmark::kMillisecond)->Iterations(10);
}

/// ForceMesh::relayout and refine_layout of layer k of the default scene at
/// two off-axis contact points, alternately.
void register_relayout(std::size_t k) {
  for (const bool refine : {false, true}) {
    const std::string name = std::string(refine ? "BM_force_mesh_refine/" : "BM_force_mesh_relayout/") +
                             std::to_string(k);
    benchmark::RegisterBenchmark(name.c_str(), [k, refine](benchmark::State& st) {
      const Setup& s = setup_for("default", default_scene());
      const Layer& layer = s.scene.layers[k];
      const LayerSurface& surface = *s.model.surfaces[k];
      MeshIntegrationSettings integration;
      integration.integrator = parse_mesh_integrator(s.scene.realtime.integrator);
      integration.time_step_s = 1.0 / s.scene.realtime.haptic_rate_Hz;
      SurfacePoint a, b;
      double t = 0.0;
      surface.intersect_ray(Eigen::Vector3d(3e-3, -2e-3, 1.0), -Eigen::Vector3d::UnitZ(), t, a);
      surface.intersect_ray(Eigen::Vector3d(-4e-3, 1e-3, 1.0), -Eigen::Vector3d::UnitZ(), t, b);
      ForceMesh mesh(surface, a, layer.force_mesh, layer.thickness_m, layer.density_kg_per_m3, integration);
      bool flip = false;
      for (auto _ : st) {
        if (!refine) {
          mesh.relayout(surface, flip ? a : b);
          flip = !flip;
        } else {
          if (!mesh.layout_pending()) {
            st.PauseTiming();
            mesh.relayout(surface, flip ? a : b);
            flip = !flip;
            st.ResumeTiming();
          }
          mesh.refine_layout(kLayoutNodesPerTick);  // the work one tick adds after an off-axis contact
        }
        benchmark::DoNotOptimize(mesh.rest_positions().data());
      }
      st.counters["mesh_nodes"] = mesh.node_count();
      if (refine)
        st.counters["ticks_to_complete"] = (mesh.node_count() - 1 + kLayoutNodesPerTick - 1) / kLayoutNodesPerTick;
    });
  }
}

/// The SH query alone and the model construction, per SH degree.
void register_sh_queries() {
  // The SH query alone: the skin's top face hit by the needle axis (what the
  // tick asks when a layer is first reached), and by vertical rays at 64
  // lateral positions spread over 0.8 R (off the pole of the parameterisation).
  for (int l : {4, 8, 16, 24, 32})
    for (const bool on_axis : {true, false})
      benchmark::RegisterBenchmark(
          ("BM_sh_intersect_ray/" + std::to_string(l) + (on_axis ? "/on_axis" : "/off_axis")).c_str(),
          [l, on_axis](benchmark::State& st) {
            const Scene scene = default_scene();
            const LayerDisc disc = layer_disc(scene, 0);
            const LayerSurface surface = LayerSurface::fit(disc.top_z_m, disc.bottom_z_m, disc.radius_m, l);
            std::vector<Eigen::Vector3d> origins;
            if (on_axis) {
              origins.emplace_back(0.0, 0.0, 0.01);
            } else {
              for (int i = 0; i < 64; ++i) {
                // Golden-angle spiral: even coverage of the disc r <= 0.8 R.
                const double r = 0.8 * disc.radius_m * std::sqrt((i + 0.5) / 64.0);
                const double a = 2.399963229728653 * i;
                origins.emplace_back(r * std::cos(a), r * std::sin(a), 0.01);
              }
            }
            const Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();
            std::size_t i = 0, misses = 0;
            double s = 0.0, z_sum = 0.0;
            SurfacePoint hit;
            for (auto _ : st) {
              if (!surface.intersect_ray(origins[i], down, s, hit)) ++misses;
              z_sum += hit.position.z();
              benchmark::DoNotOptimize(z_sum);
              i = (i + 1) % origins.size();
            }
            if (misses > 0) st.SkipWithError("a benchmark ray missed the skin surface");
          });

  for (int l : {4, 8, 16, 24, 32})
    benchmark::RegisterBenchmark(("BM_build_realtime_model/" + std::to_string(l)).c_str(),
                                 [l](benchmark::State& st) {
                                   const Scene scene = scene_with_degree(l);
                                   for (auto _ : st) {
                                     RealtimeModel m = build_realtime_model(scene);
                                     benchmark::DoNotOptimize(m.simulator.get());
                                   }
                                 })
        ->Unit(benchmark::kMillisecond);
}

void register_all() {
  const std::vector<std::string> phases{"press_skin", "after_skin_break", "inside_punctured", "in_tissue",
                                        "whole_insertion"};
  const std::vector<std::string> scaling_phases{"press_skin", "whole_insertion"};

  for (const std::string& phase : phases) {
    register_phase("BM_tick_phase/tuned/" + phase, "tuned", tuned_scene(), phase);
    register_phase("BM_tick_phase/" + phase, "default", default_scene(), phase);
  }
  register_distribution("BM_tick_distribution/tuned/whole_insertion", "tuned", tuned_scene());
  // The needle at an angle to the surface normal (needle.hpp): the tuned preset at 0, 15 and 30 deg.
  for (int angle : {0, 15, 30}) {
    Scene inclined = tuned_scene();
    inclined.insertion.angle_deg = angle;
    const std::string key = "tuned angle=" + std::to_string(angle);
    for (const std::string phase : {"press_skin", "in_tissue", "whole_insertion"})
      register_phase("BM_tick_angle/" + std::to_string(angle) + "/" + phase, key, inclined, phase);
    if (angle == 30)
      register_distribution("BM_tick_distribution/tuned_30deg/whole_insertion", key, inclined);
  }
  register_distribution("BM_tick_distribution/whole_insertion", "default", default_scene());
  register_relayout(0);
  register_relayout(2);

  for (const std::string& integrator : {std::string("quasi_static"), std::string("explicit"), std::string("implicit")})
    for (const std::string& phase : scaling_phases)
      register_phase("BM_tick_integrator/" + integrator + "/" + phase, "integrator=" + integrator,
                     scene_with_integrator(integrator), phase);

  for (int w : {2, 4, 8, 16, 32})
    for (const std::string& phase : scaling_phases)
      register_phase("BM_tick_rings_w/" + std::to_string(w) + "/" + phase, "w=" + std::to_string(w),
                     scene_with_rings(w), phase, true);

  for (int l : {4, 8, 16, 24, 32})
    for (const std::string& phase : scaling_phases)
      register_phase("BM_tick_sh_degree/" + std::to_string(l) + "/" + phase, "l=" + std::to_string(l),
                     scene_with_degree(l), phase);

  register_sh_queries();
}

}  // namespace
}  // namespace puncture::bench

int main(int argc, char** argv) {
  puncture::bench::register_all();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
