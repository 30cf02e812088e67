// bench_effects.cpp: what each effect costs in the haptic tick, and that an
// effect which is off costs (next to) nothing (DESIGN.md, user demand 3).
//
// Default scene (l = 16, implicit force mesh; its effects: surface_force,
// damping, resumption, cutting, friction), with the effects switched:
//   all_on              the default scene
//   paper               surface_force + damping + resumption (Table 1 and
//                       Eq. 8 only: cutting and friction off)
//   surface_force_off   no force meshes (and therefore no resumption); a
//                       layer breaks as soon as the tip passes its surface
//   damping_off         no d h v term
//   resumption_off      force meshes but no shape-matching resumption
//   cutting_off         no cutting force
//   friction_off        no Karnopp shaft friction
//   stiffening_on       + tip stiffening (polynomial, 0.05 N/mm^2)
//   interaction_on      + layers in series (fat and muscle break at the
//                       critical surface force they reach in the default run,
//                       1.3 N and 2.6 N, as the ring rule cannot be used with
//                       interaction)
//   all_off             none of the tick effects
// surface_output is not part of the tick (it only decides whether frames
// are written), so it is left as the scene sets it.
//
// Tuned preset (results/tuned_preset/default_tuned.json; its effects:
// surface_force, damping, resumption, cutting, friction, tip stiffening,
// coupled_surfaces, and stiffening skin and muscle force meshes):
//   all_on                  the preset
//   mesh_stiffening_off     linear force meshes (no axial surface springs, no
//                           virtual-spring stiffening): no Newton solve
//   tip_stiffening_off, cutting_off, friction_off, damping_off,
//   resumption_off, surface_force_off, all_off   as above
//
// Families (time per iteration = per tick, replayed as in bench_replay.hpp):
//   BM_effects/<config>/<phase>, BM_effects/tuned/<config>/<phase>
//   <phase> = whole_insertion              every tick of the trajectory
//   BM_effects/<config>/in_tissue          the ticks with contact (tip below
//       the skin surface): where the work is
//   BM_effects/<config>/inside_punctured   after the last puncture until the
//       target depth: damping, friction and cutting of the punctured layers,
//       resumption during its first ticks
//   BM_effects/tuned/<config>/press_skin   the skin pressed until it breaks
//       (the stiffening skin mesh's Newton solve)
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
  void (*apply)(Scene&);
  bool tuned = false;  ///< applied to the tuned preset (else to the default scene)
};

struct Setup {
  Scene scene;
  RealtimeModel model;
  InsertionScript script;
};

const Setup& setup_for(const EffectsConfig& config) {
  static std::map<std::string, std::unique_ptr<Setup>> cache;
  const std::string key = (config.tuned ? "tuned/" : "") + config.name;
  auto it = cache.find(key);
  if (it == cache.end()) {
    auto s = std::make_unique<Setup>();
    s->scene = config.tuned ? tuned_scene() : default_scene();
    config.apply(s->scene);
    validate_scene(s->scene, "bench_effects:" + key);
    s->model = build_realtime_model(s->scene);
    s->script = make_script(s->scene, s->model);
    it = cache.emplace(key, std::move(s)).first;
  }
  return *it->second;
}

/// The default scene's configurations (see the header).
std::vector<EffectsConfig> default_configs() {
  return {
      {"all_on", [](Scene&) {}},
      {"paper", [](Scene& s) { s.effects.cutting = s.effects.friction = false; }},
      {"surface_force_off", [](Scene& s) { s.effects.surface_force = s.effects.resumption = false; }},
      {"damping_off", [](Scene& s) { s.effects.damping = false; }},
      {"resumption_off", [](Scene& s) { s.effects.resumption = false; }},
      {"cutting_off", [](Scene& s) { s.effects.cutting = false; }},
      {"friction_off", [](Scene& s) { s.effects.friction = false; }},
      {"stiffening_on",
       [](Scene& s) {
         s.effects.stiffening = true;
         for (Layer& l : s.layers) l.force_law.stiffening.quadratic_N_per_m2 = 0.05e6;
       }},
      {"interaction_on",
       [](Scene& s) {
         s.effects.layer_interaction = true;
         const double critical_N[] = {2.4, 1.3, 2.6};
         for (std::size_t k = 0; k < s.layers.size() && k < 3; ++k) {
           s.layers[k].force_law.breakthrough.kind = BreakthroughCriterion::Kind::CriticalForce;
           s.layers[k].force_law.breakthrough.critical_force_N = critical_N[k];
         }
       }},
      {"all_off",
       [](Scene& s) {
         s.effects.surface_force = s.effects.damping = s.effects.resumption = false;
         s.effects.cutting = s.effects.friction = s.effects.stiffening = s.effects.layer_interaction = false;
       }},
  };
}

/// The tuned preset's configurations (see the header).
std::vector<EffectsConfig> tuned_configs() {
  return {
      {"all_on", [](Scene&) {}, true},
      {"mesh_stiffening_off",
       [](Scene& s) {
         for (Layer& l : s.layers) l.force_mesh.surface_axial_stiffness_N_per_m = l.force_mesh.virtual_stiffening_m = 0.0;
       },
       true},
      {"tip_stiffening_off", [](Scene& s) { s.effects.stiffening = false; }, true},
      {"cutting_off", [](Scene& s) { s.effects.cutting = false; }, true},
      {"friction_off", [](Scene& s) { s.effects.friction = false; }, true},
      {"damping_off", [](Scene& s) { s.effects.damping = false; }, true},
      {"resumption_off", [](Scene& s) { s.effects.resumption = false; }, true},
      {"surface_force_off", [](Scene& s) { s.effects.surface_force = s.effects.resumption = false; }, true},
      {"all_off",
       [](Scene& s) {
         s.effects.surface_force = s.effects.damping = s.effects.resumption = false;
         s.effects.cutting = s.effects.friction = s.effects.stiffening = s.effects.layer_interaction = false;
       },
       true},
  };
}

void register_all() {
  std::vector<EffectsConfig> configs = tuned_configs();
  for (const EffectsConfig& c : default_configs()) configs.push_back(c);
  for (const EffectsConfig& config : configs)
    for (const std::string phase : {"whole_insertion", "in_tissue", "inside_punctured", "press_skin"}) {
      if (phase == "press_skin" && !config.tuned) continue;
      // Built now, so the iteration count can follow the phase length.
      const Setup& s = setup_for(config);
      const TickRange range = phase == "whole_insertion" ? s.script.whole
                              : phase == "in_tissue"     ? s.script.in_tissue
                              : phase == "press_skin"    ? s.script.press_skin
                                                         : s.script.inside_punctured;
      const std::string name = std::string("BM_effects/") + (config.tuned ? "tuned/" : "") + config.name + "/" + phase;
      benchmark::RegisterBenchmark(name.c_str(),
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
