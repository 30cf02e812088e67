// tet_test_scenes.hpp: scenes for the tetrahedral-mesh and volumetric-model
// tests: the shipped default scene, and a small three-layer slab (10 mm
// across, 8 mm thick) whose mesh has a few thousand nodes.
#pragma once

#include <string>

#include "puncture/scene_io.hpp"

namespace puncture::testing {

inline Scene default_scene() { return load_scene(std::string(PUNCTURE_SOURCE_DIR) + "/scenes/default.json"); }

/// Skin 1 mm, fat 3 mm, muscle 4 mm; 10 mm across; force meshes that fit
/// (w - 1) L < 5 mm; insertion 10 mm/s to 6 mm, no dwell, quick withdrawal.
inline Scene small_slab_scene() {
  Scene s = default_scene();
  s.name = "small_slab";
  s.sample.diameter_m = 10e-3;
  const double thickness[3] = {1e-3, 3e-3, 4e-3};
  const int rings[3] = {3, 3, 3};
  const double spacing[3] = {1.5e-3, 1.5e-3, 1.5e-3};
  const double threshold[3] = {50e-6, 50e-6, 50e-6};
  for (int k = 0; k < 3; ++k) {
    s.layers[static_cast<std::size_t>(k)].thickness_m = thickness[k];
    s.layers[static_cast<std::size_t>(k)].force_mesh.rings_w = rings[k];
    s.layers[static_cast<std::size_t>(k)].force_mesh.spacing_L_m = spacing[k];
    s.layers[static_cast<std::size_t>(k)].force_mesh.deformed_threshold_m = threshold[k];
  }
  // The volumetric models take a small-strain modulus and Poisson's ratio and
  // a flat needle; these tests were set up on the neo-Hookean moduli below
  // and stay independent of the FEM physics of the shipped default scene.
  const double youngs_Pa[3] = {35e3, 2e3, 15e3};
  for (int k = 0; k < 3; ++k) {
    ContinuumMaterial& m = s.layers[static_cast<std::size_t>(k)].material;
    m.model = "neo_hookean";
    m.ogden_terms.clear();
    m.youngs_modulus_Pa = youngs_Pa[k];
    m.poisson_ratio = 0.48;
  }
  s.needle.tip = "blunt";
  s.fem.geometry = "auto";
  for (Layer& l : s.layers) {
    l.puncture.kind = PunctureCriterion::Kind::CriticalStretch;
    l.puncture.critical_stretch = 1.3;
  }
  s.insertion.start_height_m = 0.2e-3;
  s.insertion.speed_m_per_s = 0.01;
  s.insertion.target_depth_m = 6e-3;
  s.insertion.dwell_s = 0.02;
  s.insertion.withdrawal_speed_m_per_s = 0.05;
  s.comparison.mesh.size_at_axis_m = 0.5e-3;
  s.comparison.mesh.size_far_m = 2e-3;
  s.comparison.mesh.grading = 0.4;
  validate_scene(s, "small_slab_scene");
  return s;
}

/// One soft layer (E = 10 kPa), 6 mm thick, 16 mm across; a force mesh that
/// never breaks; indented 0.03 mm at 1 mm/s (small strain, quasi-static).
inline Scene single_layer_scene(double poisson, double size_at_axis_m) {
  Scene s = small_slab_scene();
  s.layers.resize(1);
  s.layers[0].thickness_m = 6e-3;
  s.layers[0].material.youngs_modulus_Pa = 10e3;
  s.layers[0].material.poisson_ratio = poisson;
  s.layers[0].force_mesh.deformed_threshold_m = 1.0;  // no puncture
  s.sample.diameter_m = 16e-3;
  s.insertion.start_height_m = 0.0;
  s.insertion.target_depth_m = 0.03e-3;
  s.insertion.speed_m_per_s = 0.001;
  s.comparison.mesh.size_at_axis_m = size_at_axis_m;
  s.comparison.mesh.size_far_m = 2.5e-3;
  s.comparison.mesh.grading = 0.4;
  validate_scene(s, "single_layer_scene");
  return s;
}

}  // namespace puncture::testing
