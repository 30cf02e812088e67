// The axisymmetric reference over a whole trajectory (insertion, dwell,
// withdrawal) on a small version of the default scene: the default's
// materials, fracture energies, friction and needle, on a 30 mm wide slab with
// thinner fat and muscle, coarse mesh. What is checked could each fail:
// layers break in depth order, the skin's puncture force and depth are those
// of the same slab on a twice finer mesh (a convergence check), friction is
// there after puncture and reverses on withdrawal, the numerical
// stabilisation dissipates a small share of the needle's work, and nothing is
// NaN. Hard cases: a brittle skin punctures, a very tough one does not.
#include <deal.II/base/mpi.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <puncture/fem/needle_insertion.hpp>
#include <puncture/scene_io.hpp>

#include "fem_test_scenes.hpp"
#include <string>

using namespace puncture;
using namespace puncture::fem;
using puncture::fem::testing::quiet;

namespace {

Scene small_default_scene() {
  Scene s = load_scene(std::filesystem::path(PUNCTURE_SOURCE_DIR) / "scenes" / "default.json");
  s.name = "small_default";
  s.sample.diameter_m = 30e-3;
  s.layers[1].thickness_m = 3e-3;
  s.layers[2].thickness_m = 6e-3;
  s.insertion.start_height_m = 0.5e-3;
  s.insertion.target_depth_m = 7e-3;
  s.insertion.dwell_s = 0.04;
  s.fem.geometry = "axisymmetric";
  s.fem.load_step_m = 0.2e-3;
  s.fem.mesh.elements_per_needle_radius = 4;
  s.fem.mesh.path_element_size_mm = 0.4;
  return s;
}

}  // namespace

TEST(AxisymmetricInsertion, SmallDefaultSlabPuncturesInOrderWithFrictionThatReversesOnWithdrawal) {
  const Scene s = small_default_scene();
  ASSERT_EQ(s.needle.tip, "bevel");
  ASSERT_EQ(s.layers[0].puncture.kind, PunctureCriterion::Kind::FractureEnergy);
  const FemRunSummary r = run_needle_insertion(s, quiet(), MPI_COMM_WORLD);
  ASSERT_EQ(r.geometry, "axisymmetric");
  for (std::size_t k = 0; k < r.force_N.size(); ++k) {
    ASSERT_TRUE(std::isfinite(r.force_N[k])) << "row " << k;
    ASSERT_TRUE(std::isfinite(r.friction_force_N[k])) << "row " << k;
  }

  // Skin first, then fat, each at a deeper tip position than the one before.
  ASSERT_GE(r.punctures.size(), 2u);
  EXPECT_EQ(r.punctures[0].layer_name, "skin");
  EXPECT_EQ(r.punctures[1].layer_name, "fat");
  for (std::size_t i = 1; i < r.punctures.size(); ++i) EXPECT_GE(r.punctures[i].depth_m, r.punctures[i - 1].depth_m);
  // It punctures after a visible tenting of the surface, not at first touch.
  EXPECT_GT(r.punctures[0].depth_m, 1e-3);
  // Convergence: the same slab on a mesh twice as fine (tip and path elements
  // halved), run only until just past the skin puncture, gives the same skin
  // puncture. Tolerance 2 % of the force, one load step (0.2 mm) of the depth:
  // on the default slab these two meshes differ by 0.28 % in force and not at
  // all in depth (results/fem_puncture_mesh_independence.md), on this slab by
  // 0.4 % (3.094 N against 3.082 N, both at 5.0 mm); 2 % is five times that,
  // and far below the 10 % the mesh study aims at.
  {
    Scene fine = s;
    fine.fem.mesh.elements_per_needle_radius = 8;
    fine.fem.mesh.path_element_size_mm = 0.2;
    FemRunOptions o = quiet();
    o.stop_depth_m = r.punctures[0].depth_m + 0.6e-3;
    const FemRunSummary f = run_needle_insertion(fine, o, MPI_COMM_WORLD);
    ASSERT_GE(f.punctures.size(), 1u) << "the fine mesh's skin punctures by " << o.stop_depth_m * 1e3 << " mm";
    EXPECT_EQ(f.punctures[0].layer_name, "skin");
    EXPECT_NEAR(f.punctures[0].force_N, r.punctures[0].force_N, 0.02 * r.punctures[0].force_N);
    EXPECT_NEAR(f.punctures[0].depth_m, r.punctures[0].depth_m, s.fem.load_step_m + 1e-9);
  }

  // After the skin puncture the force does not fall to zero (cutting and
  // friction), and friction acts on the shaft while inserting.
  const double skin_depth = r.punctures[0].depth_m;
  double min_after = 1e9, max_friction_in = 0.0, min_friction_out = 0.0;
  for (std::size_t k = 0; k < r.force_N.size(); ++k) {
    if (r.phase[k] == "insertion" && r.depth_m[k] > skin_depth + 0.5e-3) {
      min_after = std::min(min_after, r.force_N[k]);
      max_friction_in = std::max(max_friction_in, r.friction_force_N[k]);
    }
    if (r.phase[k] == "withdrawal") min_friction_out = std::min(min_friction_out, r.friction_force_N[k]);
  }
  EXPECT_GT(min_after, 0.1) << "force after the skin puncture";
  EXPECT_GT(max_friction_in, 0.01) << "shaft friction while inserting (N)";
  // Withdrawal: the shaft friction drags the tissue up, the force on the needle reverses.
  EXPECT_LT(min_friction_out, -0.005) << "shaft friction while withdrawing (N)";

  // The numerical stabilisation is a small share of the needle's work; the
  // crack dissipates a real part of it.
  ASSERT_GT(r.needle_work_J, 0.0);
  EXPECT_LT(r.stabilization_dissipation_J, 0.02 * r.needle_work_J);
  EXPECT_GT(r.cohesive_dissipation_J, 0.0);
  // The crack's dissipation is the cutting part's work over the advancing
  // steps plus what crack runs released (stored energy, not needle force),
  // plus what it dissipates while the needle holds or withdraws: so the
  // first two sum to at most the whole.
  double cutting_work_J = 0.0;
  for (std::size_t k = 1; k < r.force_N.size(); ++k)
    if (r.depth_m[k] > r.depth_m[k - 1]) cutting_work_J += r.cutting_force_N[k] * (r.depth_m[k] - r.depth_m[k - 1]);
  EXPECT_GT(cutting_work_J, 0.0);
  EXPECT_GE(r.crack_energy_released_J, 0.0);
  EXPECT_LE(cutting_work_J + r.crack_energy_released_J, r.cohesive_dissipation_J * (1.0 + 1e-9));
  EXPECT_LE(r.crack_energy_released_J, r.cohesive_dissipation_J);
}

TEST(AxisymmetricInsertion, WithoutFrictionTheWithdrawalForceIsNeverNegative) {
  // The same slab with frictionless layers: nothing can pull the needle
  // back, so the force on withdrawal stays >= 0 (up to the solver tolerance),
  // and the friction column is zero throughout.
  Scene s = small_default_scene();
  for (auto& l : s.layers) l.shaft_friction = ShaftFriction{};
  s.insertion.target_depth_m = 6e-3;
  const FemRunSummary r = run_needle_insertion(s, quiet(), MPI_COMM_WORLD);
  for (std::size_t k = 0; k < r.force_N.size(); ++k) {
    EXPECT_EQ(r.friction_force_N[k], 0.0) << "row " << k;
    if (r.phase[k] == "withdrawal") EXPECT_GT(r.force_N[k], -1e-4) << "row " << k;
  }
  ASSERT_GE(r.punctures.size(), 1u);
  EXPECT_EQ(r.punctures[0].layer_name, "skin");
}

/// The small slab with nearly incompressible layers (nu 0.499), to 4 mm and
/// back, with the skin's fracture energy G_c (J/m^2) set.
Scene hard_case(double skin_toughness_J_per_m2) {
  Scene s = small_default_scene();
  s.layers[0].puncture.toughness_J_per_m2 = skin_toughness_J_per_m2;
  for (auto& l : s.layers) l.material.poisson_ratio = 0.499;
  s.insertion.target_depth_m = 4e-3;
  return s;
}

void expect_finite_rows(const FemRunSummary& r) {
  for (std::size_t k = 0; k < r.force_N.size(); ++k)
    ASSERT_TRUE(std::isfinite(r.force_N[k]) && std::isfinite(r.friction_force_N[k])) << "row " << k;
}

TEST(AxisymmetricInsertion, HardCaseBrittleSkinConvergesAndPunctures) {
  // G_c = 1 J/m^2: the cohesive law opens fully within 2 G_c / sigma_c = 1 um
  // once the traction reaches sigma_c (2 MPa), so the skin cuts as soon as the
  // tip stretches it that far: the run completes and the skin (only) punctures
  // within the 4 mm. (With sigma_c fixed, the puncture force is governed by
  // sigma_c more than by G_c: a brittle skin still needs sigma_c to open.)
  const FemRunSummary r = run_needle_insertion(hard_case(1.0), quiet(), MPI_COMM_WORLD);
  expect_finite_rows(r);
  ASSERT_EQ(r.punctures.size(), 1u);
  EXPECT_EQ(r.punctures[0].layer_name, "skin");
  EXPECT_LE(r.punctures[0].depth_m, 4e-3 + 1e-9);
  EXPECT_GT(r.punctures[0].force_N, 0.0);
}

TEST(AxisymmetricInsertion, HardCaseVeryToughSkinConvergesAndDoesNotPuncture) {
  // G_c = 30 000 J/m^2: full separation needs a separation of 2 G_c / sigma_c =
  // 30 mm, and the bevel can open the law's separation at most to its width
  // 2a = 1.27 mm (LayerCrack: the ring's radial opening a - r_c times
  // opening_scale); steady cutting would need G_c x 2a = 38 N. The run
  // completes with finite forces, no layer punctures, the force stays below 38 N.
  const FemRunSummary r = run_needle_insertion(hard_case(30000.0), quiet(), MPI_COMM_WORLD);
  expect_finite_rows(r);
  EXPECT_TRUE(r.punctures.empty()) << r.punctures.size() << " punctures, the first " << r.punctures[0].layer_name;
  const double peak = *std::max_element(r.force_N.begin(), r.force_N.end());
  EXPECT_GT(peak, 0.0);
  EXPECT_LT(peak, 38.0);
}

TEST(AxisymmetricInsertion, WarnsWhenTheMeshIsTooCoarseForTheAccuracyTarget) {
  // results/fem_axisymmetric_convergence.md: Q1 needs 4 elements per needle
  // radius and every layer a few elements through its thickness. The scene's
  // own resolution gets no mesh warning; 2 per radius, or a layer with 2
  // elements through its thickness, does. Only the first millimetre is run (warnings come first).
  auto mesh_warnings = [](const Scene& s) {
    FemRunOptions o = quiet();
    o.stop_depth_m = 0.4e-3;
    const FemRunSummary r = run_needle_insertion(s, o, MPI_COMM_WORLD);
    std::string all;
    for (const auto& w : r.warnings)
      if (w.rfind("mesh:", 0) == 0) all += w + "\n";
    return all;
  };
  Scene s = small_default_scene();
  s.insertion.start_height_m = 0.0;
  EXPECT_EQ(mesh_warnings(s), "");
  Scene coarse = s;
  coarse.fem.mesh.elements_per_needle_radius = 2;
  EXPECT_NE(mesh_warnings(coarse).find("elements per needle radius"), std::string::npos);
  Scene thin = s;
  thin.fem.mesh.elements_per_needle_radius = 2;  // first element 0.32 mm at each layer top
  thin.fem.mesh.min_elements_per_layer = 2;
  thin.fem.mesh.path_element_size_mm = 2.0;
  thin.layers[1].thickness_m = 0.8e-3;  // fat: 0.32 mm, then 0.38 mm, then the rest
  EXPECT_NE(mesh_warnings(thin).find("elements through its thickness"), std::string::npos) << mesh_warnings(thin);
}
