// fem_test_scenes.hpp: small scenes for the FEM tests (coarse, fast).
#pragma once

#include <puncture/fem/needle_insertion.hpp>
#include <puncture/scene.hpp>

namespace puncture::fem::testing {

inline Layer make_layer(const std::string& name, double thickness_m, double E_Pa, double nu,
                        double critical_force_N) {
  Layer l;
  l.name = name;
  l.thickness_m = thickness_m;
  l.material.model = "neo_hookean";
  l.material.youngs_modulus_Pa = E_Pa;
  l.material.poisson_ratio = nu;
  l.puncture.kind = PunctureCriterion::Kind::CriticalForce;
  l.puncture.critical_force_N = critical_force_N;
  return l;
}

/// Three layers, 16 mm wide sample, 18 G needle, 0.25 mm load steps.
inline Scene small_three_layer_scene() {
  Scene s;
  s.name = "fem_test_three_layers";
  s.sample.diameter_m = 0.016;
  s.layers = {make_layer("skin", 0.8e-3, 2.0e5, 0.45, 0.05), make_layer("fat", 2.5e-3, 2.0e4, 0.45, 0.03),
              make_layer("muscle", 4.0e-3, 5.0e4, 0.45, 100.0)};
  s.needle.radius_m = 0.635e-3;
  s.insertion.start_height_m = 0.5e-3;
  s.insertion.speed_m_per_s = 0.01;
  s.insertion.target_depth_m = 5e-3;
  s.fem.load_step_m = 0.25e-3;
  s.fem.refinement = 0;
  s.fem.element_degree = 1;
  s.fem.geometry = "3d";
  return s;
}

/// Coarse mesh options for tests.
inline meshing::SlabMeshOptions coarse_mesh() {
  meshing::SlabMeshOptions m;
  m.elements_through_skin = 2;
  m.sectors = 8;
  m.radial_grading = 1.6;
  m.thickness_grading = 1.6;
  return m;
}

/// Run options of a test: nothing printed, no files written.
inline FemRunOptions quiet() {
  FemRunOptions o;
  o.verbose = false;
  o.write_files = false;
  o.write_vtu = false;
  return o;
}

}  // namespace puncture::fem::testing
