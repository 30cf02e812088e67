// bench_comparison_step.cpp: cost of one haptic step of every comparison
// model of `puncture compare` (core/models) against its resolution, on the
// default scene (scenes/default.json) while the needle presses the skin.
//
// BM_comparison_step/<model>/<resolution>:
//   volumetric models (msm, mass_tensor, nonlinear_mass_tensor,
//   viscoelastic_mass_tensor): the CGAL tetrahedral mesh of the default scene
//   with its comparison.mesh options, on samples of diameter 32, 44 and 60 mm
//   (the default; scene_with_diameter). The diameter, not the size options, is the knob:
//   on this slab the vertex count hardly depends on size_at_axis / size_far
//   (BM_build_tet_mesh/size_x*: the 0.8 mm skin layer, whose two faces
//   Mesh_3 must sample densely over the whole disc, holds two thirds of the
//   vertices), so it grows with the disc's area;
//   bem: the number of annular boundary elements on the needle disc;
//   shf, realtime: the SH degree of the layer surfaces (realtime.sh_degree).
// One benchmark run = a fresh model (built untimed), advanced untimed from
// t = 0 until the tip is kWindowStartDepth_m below the skin surface, then
// kWindowSteps haptic steps (1 kHz, 10 mm/s: 0.01 mm each), each timed alone
// by steady_clock (manual time): time per iteration = the mean time of one
// step in the window. Counters: dofs and nodes (ModelSize), step_median_us
// (median single-step time in the window), skin_pressed_fraction (share of
// the window's steps after which the skin was pressed and unbroken: 1 when
// every step measured the same phase), memory_MB.
// BM_build_tet_mesh/size_x<s>/diameter_<d>mm: the CGAL mesh with the size
// options times s (one iteration) and where its vertices lie (counters).
// Environment: BENCH_COMPARISON_REPORT=1 prints each volumetric run's
// integrator statistics (steps, factorisations and their time) to stderr;
// BENCH_WINDOW_START_MM moves the window (diagnostics; the committed table
// uses 0.2 mm).
// Run through scripts/comparison_cost.py, which writes results/comparison_cost/.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "puncture/comparison/model_factory.hpp"
#include "puncture/comparison/surface_models.hpp"
#include "puncture/meshing/tet_slab_mesh.hpp"
#include "puncture/needle.hpp"
#include "puncture/scene_io.hpp"

namespace puncture::bench {
namespace {

constexpr double kWindowStartDepth_m = 0.2e-3;
constexpr int kWindowSteps = 100;
/// Sample diameters of the volumetric family (mm): 60 is the default scene's.
constexpr double kDiameters_mm[] = {32.0, 44.0, 60.0};

const Scene& default_scene() {
  static const Scene scene = load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json");
  return scene;
}

/// The default scene with another sample diameter (mm). A layer whose
/// force-mesh lattice would not fit (ring w at (w - 1) L beyond 0.9 R) gets
/// its spacing L shrunk to fit, as results/comparison/small_slab.json does;
/// the skin's (ring 8 at 14 mm) fits every diameter used here, so the
/// measured phase, the skin pressed, is the default scene's.
Scene scene_with_diameter(double diameter_mm) {
  Scene scene = default_scene();
  scene.sample.diameter_m = diameter_mm * 1e-3;
  const double radius = 0.5 * scene.sample.diameter_m;
  for (Layer& layer : scene.layers) {
    ForceMeshParams& f = layer.force_mesh;
    if ((f.rings_w - 1) * f.spacing_L_m > 0.9 * radius) f.spacing_L_m = 0.9 * radius / (f.rings_w - 1);
  }
  validate_scene(scene, "bench_comparison_step: diameter " + std::to_string(diameter_mm) + " mm");
  return scene;
}

std::shared_ptr<const meshing::TetMesh> mesh_for(double diameter_mm) {
  static std::map<double, std::shared_ptr<const meshing::TetMesh>> cache;
  auto it = cache.find(diameter_mm);
  if (it == cache.end()) {
    const Scene scene = scene_with_diameter(diameter_mm);
    it = cache.emplace(diameter_mm, std::make_shared<const meshing::TetMesh>(meshing::build_tet_slab_mesh(
                                        scene, meshing::tet_slab_mesh_options(scene))))
             .first;
  }
  return it->second;
}

struct Config {
  std::string model;
  double diameter_mm = 60.0;  ///< volumetric: sample diameter (the mesh size follows it)
  int resolution = 0;         ///< bem elements / SH degree
};

std::unique_ptr<comparison::ComparisonModel> build(const Config& c, Scene& scene) {
  if (comparison::is_volumetric_model(c.model))
    return comparison::make_comparison_model(c.model, scene, mesh_for(c.diameter_mm));
  if (c.model == "bem") {
    comparison::BemSettings settings;
    settings.elements_in_contact = c.resolution;
    return std::make_unique<comparison::BoundaryElementModel>(scene, settings);
  }
  scene.realtime.sh_degree = c.resolution;
  return comparison::make_comparison_model(c.model, scene, nullptr);
}

void BM_comparison_step(benchmark::State& state, const Config& config) {
  Scene scene = scene_with_diameter(config.diameter_mm);
  const ScriptedTrajectory trajectory(scene.insertion);
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  std::unique_ptr<comparison::ComparisonModel> model = build(config, scene);
  long step = 0;
  double window_start_m = kWindowStartDepth_m;
  if (const char* d = std::getenv("BENCH_WINDOW_START_MM")) window_start_m = 1e-3 * std::atof(d);  // diagnostics
  while (trajectory.sample(static_cast<double>(step) * dt).depth_m() < window_start_m)
    model->step(trajectory.sample(static_cast<double>(step++) * dt));
  std::vector<double> times_s;
  times_s.reserve(kWindowSteps);
  int pressed_steps = 0;
  for (auto _ : state) {
    const NeedleState needle = trajectory.sample(static_cast<double>(step++) * dt);
    const auto start = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(model->step(needle));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    state.SetIterationTime(seconds);
    times_s.push_back(seconds);
    if (model->layer_state(0) == LayerState::Pressed) ++pressed_steps;
  }
  const comparison::ModelSize size = model->model_size();
  if (std::getenv("BENCH_COMPARISON_REPORT")) std::fprintf(stderr, "%s: %s\n", config.model.c_str(), model->integrator_report().c_str());
  std::nth_element(times_s.begin(), times_s.begin() + static_cast<long>(times_s.size() / 2), times_s.end());
  state.counters["step_median_us"] = times_s.empty() ? 0.0 : 1e6 * times_s[times_s.size() / 2];
  state.counters["dofs"] = static_cast<double>(size.dofs);
  state.counters["nodes"] = static_cast<double>(size.nodes);
  state.counters["memory_MB"] = static_cast<double>(size.memory_bytes) / 1e6;
  state.counters["skin_pressed_fraction"] = static_cast<double>(pressed_steps) / static_cast<double>(kWindowSteps);
}

/// CGAL meshing of the default slab at a size factor (outside the haptic
/// loop; one iteration: the mesh is built once per process).
void BM_build_tet_mesh(benchmark::State& state, double factor, double diameter_mm) {
  const Scene scene = scene_with_diameter(diameter_mm);
  meshing::TetSlabMeshOptions options = meshing::tet_slab_mesh_options(scene);
  options.size_at_axis_m *= factor;
  options.size_far_m *= factor;
  meshing::TetMesh mesh;
  for (auto _ : state) mesh = meshing::build_tet_slab_mesh(scene, options);
  state.counters["vertices"] = mesh.node_count();
  // Where the vertices are: near the needle column, within 5 mm of the axis, on the sample's side.
  const double a = scene.needle.radius_m, R = 0.5 * scene.sample.diameter_m;
  const double skin_bottom = -scene.layers[0].thickness_m - 1e-7;
  int column = 0, near = 0, side = 0, skin = 0;
  for (int i = 0; i < mesh.node_count(); ++i) {
    const double r = mesh.points_m.col(i).head<2>().norm();
    column += r < 2.0 * a;
    near += r < 5e-3;
    side += r > R - 1e-6;
    skin += mesh.points_m(2, i) >= skin_bottom;
  }
  state.counters["vertices_in_skin"] = skin;
  state.counters["vertices_r_below_2a"] = column;
  state.counters["vertices_r_below_5mm"] = near;
  state.counters["vertices_on_side"] = side;
  state.counters["tetrahedra"] = mesh.tet_count();
}

void register_all() {
  for (double factor : {2.0, 1.4, 1.0, 0.7})
    benchmark::RegisterBenchmark(("BM_build_tet_mesh/size_x" + std::to_string(factor).substr(0, 3) + "/diameter_60mm").c_str(),
                                 BM_build_tet_mesh, factor, 60.0)
        ->Iterations(1)
        ->Unit(benchmark::kMillisecond);
  for (double diameter : kDiameters_mm)
    benchmark::RegisterBenchmark(("BM_build_tet_mesh/size_x1.0/diameter_" + std::to_string(int(diameter)) + "mm").c_str(),
                                 BM_build_tet_mesh, 1.0, diameter)
        ->Iterations(1)
        ->Unit(benchmark::kMillisecond);
  std::vector<Config> configs;
  for (const char* model : {"msm", "mass_tensor", "nonlinear_mass_tensor", "viscoelastic_mass_tensor"})
    for (double diameter : kDiameters_mm) configs.push_back({model, diameter, 0});
  for (int elements : {8, 16, 32, 64}) configs.push_back({"bem", 60.0, elements});
  for (const char* model : {"shf", "realtime"})
    for (int degree : {8, 16, 32}) configs.push_back({model, 60.0, degree});
  for (const Config& c : configs) {
    std::ostringstream name;
    name << "BM_comparison_step/" << c.model << "/";
    if (comparison::is_volumetric_model(c.model))
      name << "diameter_" << static_cast<int>(c.diameter_mm) << "mm";
    else
      name << (c.model == "bem" ? "elements_" : "sh_degree_") << c.resolution;
    benchmark::RegisterBenchmark(name.str().c_str(), BM_comparison_step, c)
        ->Iterations(kWindowSteps)
        ->UseManualTime()
        ->Unit(benchmark::kMicrosecond);
  }
}

}  // namespace
}  // namespace puncture::bench

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  puncture::bench::register_all();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
