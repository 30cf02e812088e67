// bench_effects.cpp: what each effect costs in the haptic tick, and that an
// effect which is off costs (next to) nothing (DESIGN.md, user demand 3).
//
// Default scene (l = 16, implicit force mesh), with the effects switched:
//   all_on              surface_force + damping + resumption (the default)
//   surface_force_off   no force meshes (and therefore no resumption); a
//                       layer breaks as soon as the tip passes its surface
//   damping_off         no d h v term
//   resumption_off      force meshes but no shape-matching resumption
//   all_off             none of the three
// surface_output is not part of the tick (it only decides whether frames
// are written), so it is left as the scene sets it.
//
// Families (time per iteration = per tick, replayed as in bench_replay.hpp):
//   BM_effects/<config>/whole_insertion    every tick of the trajectory
//   BM_effects/<config>/inside_punctured   after the last puncture until the
//       target depth: damping of every punctured layer, resumption during
//       its first ceil(1 / eta_r) ticks
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench_replay.hpp"

namespace puncture::bench {
namespace {

struct EffectsConfig {
  std::string name;
  bool surface_force, damping, resumption;
};

struct Setup {
  Scene scene;
  RealtimeModel model;
  InsertionScript script;
};

const Setup& setup_for(const EffectsConfig& config) {
  static std::map<std::string, std::unique_ptr<Setup>> cache;
  auto it = cache.find(config.name);
  if (it == cache.end()) {
    auto s = std::make_unique<Setup>();
    s->scene = default_scene();
    s->scene.effects.surface_force = config.surface_force;
    s->scene.effects.damping = config.damping;
    s->scene.effects.resumption = config.resumption;
    validate_scene(s->scene, "bench_effects:" + config.name);
    s->model = build_realtime_model(s->scene);
    s->script = make_script(s->scene, s->model);
    it = cache.emplace(config.name, std::move(s)).first;
  }
  return *it->second;
}

void register_all() {
  const std::vector<EffectsConfig> configs{
      {"all_on", true, true, true},         {"surface_force_off", false, true, false},
      {"damping_off", true, false, true},   {"resumption_off", true, true, false},
      {"all_off", false, false, false},
  };
  for (const EffectsConfig& config : configs)
    for (const std::string phase : {"whole_insertion", "inside_punctured"}) {
      // Built now, so the iteration count can follow the phase length.
      const Setup& s = setup_for(config);
      const TickRange range = phase == "whole_insertion" ? s.script.whole : s.script.inside_punctured;
      benchmark::RegisterBenchmark(("BM_effects/" + config.name + "/" + phase).c_str(),
                                   [&s, range](benchmark::State& st) {
                                     run_replay(st, s.scene, s.model, s.script, range);
                                   })
          ->Iterations(replay_iterations(range));
    }
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
