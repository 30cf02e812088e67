// table2_scene.hpp (test helper): the seed paper's Table 2 three-layer scene
// with the force-mesh defaults proposed for scenes/default.json, and flat
// PlaneSurface layer tops.
#pragma once

#include <memory>
#include <vector>

#include "puncture/contact_surface.hpp"
#include "puncture/scene.hpp"

namespace puncture::test {

inline Layer table2_layer(const char* name, double thickness_m, double K_N_per_m, double d_N_s_per_m2, int w,
                          double L_m, double ks_N_per_m, double threshold_m, double node_damping) {
  Layer l;
  l.name = name;
  l.thickness_m = thickness_m;
  l.damping_N_s_per_m2 = d_N_s_per_m2;
  l.force_mesh.virtual_stiffness_N_per_m = K_N_per_m;
  l.force_mesh.rings_w = w;
  l.force_mesh.spacing_L_m = L_m;
  l.force_mesh.surface_stiffness_N_per_m = ks_N_per_m;
  l.force_mesh.deformed_threshold_m = threshold_m;
  l.force_mesh.node_damping_N_s_per_m = node_damping;
  return l;
}

/// Table 2 (thickness cm -> m, K N/mm -> N/m, d N s/m per mm -> N s/m^2, L mm -> m).
inline Scene table2_scene(const char* integrator = "implicit") {
  Scene s;
  s.name = "table2";
  s.layers.push_back(table2_layer("skin", 0.8e-3, 160.0, 3000.0, 8, 2e-3, 200.0, 10e-6, 0.05));
  s.layers.push_back(table2_layer("fat", 8.4e-3, 80.0, 1000.0, 4, 1e-3, 50.0, 0.15e-3, 0.05));
  s.layers.push_back(table2_layer("muscle", 39e-3, 230.0, 3000.0, 10, 2.5e-3, 200.0, 0.7e-6, 0.5));
  s.realtime.integrator = integrator;
  return s;
}

/// Flat layer tops: plane z = -(depth of the layer's top).
inline std::vector<std::unique_ptr<ContactSurface>> plane_surfaces(const Scene& s) {
  std::vector<std::unique_ptr<ContactSurface>> surfaces;
  for (std::size_t k = 0; k < s.layers.size(); ++k)
    surfaces.push_back(std::make_unique<PlaneSurface>(-s.layer_top_depth_m(k)));
  return surfaces;
}

}  // namespace puncture::test
