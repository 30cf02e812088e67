// Needle insertion on coarse slabs: indentation stiffness against Sneddon's
// flat punch, puncture sequence with spring-back, output files, hard cases.
#include <deal.II/base/mpi.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <vector>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "fem_test_scenes.hpp"

using namespace puncture;
using namespace puncture::fem;
using namespace puncture::fem::testing;

namespace {

std::filesystem::path fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::path(PUNCTURE_BINARY_DIR) / "test_output" / name;
  std::filesystem::remove_all(dir);
  return dir;
}

FemRunOptions quiet_options(const std::string& dir) {
  FemRunOptions o;
  o.output_dir = dir;
  o.mesh = coarse_mesh();
  o.verbose = false;
  o.write_files = !dir.empty();
  o.write_vtu = false;
  return o;
}

}  // namespace

TEST(NeedleInsertion, SmallIndentationStiffnessMatchesSneddonFlatPunch) {
  // One thick layer (h = 20 a, sample radius 16 a), nu = 0.499: the initial
  // slope of a rigid flat cylinder of radius a held on the surface is
  // Sneddon's 2 E a / (1 - nu^2) (for nu -> 0.5 the bonded and the
  // frictionless punch coincide) times the bottom effect of a layer bonded to
  // a rigid base (Garcia & Garcia 2018, chi = a / h = 0.05: 1.060). The
  // coarse 3D Q1 meshes are too stiff (results/fem_mesh_convergence.md): this
  // checks that they converge to the closed form within 3 %.
  Scene s;
  s.name = "sneddon";
  const double a = 0.635e-3, E = 1e4, nu = 0.499, h = 20 * a;
  s.sample.diameter_m = 32 * a;
  // Two layers of the same material: the thin top one only grades the mesh
  // (element height about a/3 under the punch, growing downward).
  s.layers = {make_layer("top", 0.5e-3, E, nu, 1e9), make_layer("bulk", h - 0.5e-3, E, nu, 1e9)};
  s.needle.radius_m = a;
  s.insertion.start_height_m = 0.0;
  s.insertion.target_depth_m = 0.01 * a;
  s.fem.load_step_m = 0.01 * a;
  FemRunOptions o = quiet_options("");
  o.mesh.sectors = 12;
  o.mesh.radial_grading = 1.3;
  o.mesh.elements_through_skin = 2;
  o.mesh.thickness_grading = 1.3;
  const double chi = a / h;
  const double bottom = 1 + 1.133 * chi + 1.283 * chi * chi + 0.769 * std::pow(chi, 3) + 0.0975 * std::pow(chi, 4);
  const double exact = 2.0 * E * a / (1.0 - nu * nu) * bottom;
  double ratio[2] = {0, 0};
  for (int refinement : {0, 1}) {
    o.refinement_override = refinement;
    const FemRunSummary r = run_needle_insertion(s, o, MPI_COMM_WORLD);
    ASSERT_GE(r.depth_m.size(), 2u);
    ratio[refinement] = r.force_N.back() / r.depth_m.back() / exact;
  }
  // The punch edge is singular (stress ~ r^-1/2), so the force converges at
  // first order in h: Q1 meshes approach from above, and the Richardson
  // extrapolation 2 F_1 - F_0 of refinements 0 and 1 is the converged slope.
  EXPECT_GT(ratio[0], ratio[1]) << "the unrefined mesh is the stiffer one";
  EXPECT_GT(ratio[1], 1.0) << "Q1 converges from above";
  EXPECT_NEAR(2 * ratio[1] - ratio[0], 1.0, 0.03) << "refinement 0: " << ratio[0] << ", refinement 1: " << ratio[1];
}

TEST(NeedleInsertion, PuncturesSkinThenFatWithSpringBackAndWritesFiles) {
  const Scene s = small_three_layer_scene();
  const auto dir = fresh_dir("three_layers");
  FemRunOptions o = quiet_options(dir.string());
  o.write_vtu = true;
  o.stop_depth_m = 3.0e-3;
  const FemRunSummary r = run_needle_insertion(s, o, MPI_COMM_WORLD);

  // No force before the tip reaches the skin; finite forces everywhere.
  for (std::size_t i = 0; i < r.depth_m.size(); ++i) {
    ASSERT_TRUE(std::isfinite(r.force_N[i]));
    if (r.depth_m[i] < 0.0) EXPECT_EQ(r.force_N[i], 0.0);
  }
  ASSERT_GE(r.punctures.size(), 2u);
  EXPECT_EQ(r.punctures[0].layer_name, "skin");
  EXPECT_EQ(r.punctures[1].layer_name, "fat");
  EXPECT_GE(r.punctures[0].force_N, s.layers[0].puncture.critical_force_N);
  EXPECT_GE(r.punctures[1].force_N, s.layers[1].puncture.critical_force_N);
  EXPECT_LT(r.punctures[1].depth_m, 3.0e-3 + 1e-12);
  EXPECT_GT(r.punctures[1].depth_m, r.punctures[0].depth_m);
  // The force drops at breakthrough (the skin's resistance is gone).
  EXPECT_LT(r.punctures[0].force_after_N, 0.8 * r.punctures[0].force_N);
  // Before the skin breaks, the force grows with depth.
  for (std::size_t i = 1; i < r.depth_m.size() && r.depth_m[i] < r.punctures[0].depth_m; ++i)
    if (r.depth_m[i] > 0.0) EXPECT_GT(r.force_N[i], r.force_N[i - 1]);

  // Files: CSV header, summary JSON, recovery profile, VTU series.
  std::ifstream csv(dir / "fem_force_depth.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header, "time_s,depth_mm,velocity_mm_per_s,force_N,tip_stretch,skin_state,fat_state,muscle_state");
  std::ifstream js(dir / "fem_summary.json");
  const auto j = nlohmann::json::parse(js);
  EXPECT_EQ(j["status"], "completed");
  EXPECT_EQ(j["punctures"].size(), r.punctures.size());
  // The fields both drivers write (common_summary_json) and this driver's own.
  EXPECT_EQ(j["n_dofs"].get<std::size_t>(), r.n_dofs);
  EXPECT_EQ(j["n_cells"].get<std::size_t>(), r.n_cells);
  EXPECT_EQ(j["load_steps"].get<int>(), r.load_steps);
  EXPECT_EQ(j["newton_iterations"].get<int>(), r.newton_iterations);
  EXPECT_DOUBLE_EQ(j["peak_force_N"].get<double>(), r.peak_force_N);
  EXPECT_DOUBLE_EQ(j["peak_force_depth_mm"].get<double>(), r.peak_force_depth_m * 1e3);
  EXPECT_DOUBLE_EQ(j["punctures"][0]["depth_mm"].get<double>(), r.punctures[0].depth_m * 1e3);
  EXPECT_TRUE(j["punctures"][0].contains("max_stretch"));
  EXPECT_EQ(j["n_ranks"].get<int>(), r.n_ranks);
  EXPECT_EQ(j["puncture_bisections"].get<int>(), r.bisections);
  EXPECT_TRUE(j.contains("files") && j.contains("warnings") && j.contains("element_degree") &&
              j.contains("refinement") && j.contains("load_step_mm") && j.contains("wall_time_s"));
  EXPECT_TRUE(std::filesystem::exists(dir / "fem_fields.pvd"));
  EXPECT_TRUE(std::filesystem::exists(dir / "fem_surface_profile.csv"));
  std::ifstream rec(dir / "fem_recovery_profile.csv");
  std::string line;
  int before = 0, after = 0;
  double uz_axis_before = 0.0, uz_axis_after = 0.0;
  std::getline(rec, line);
  while (std::getline(rec, line)) {
    std::stringstream ss(line);
    std::string layer, phase, depth, r_mm, uz;
    std::getline(ss, layer, ',');
    std::getline(ss, phase, ',');
    std::getline(ss, depth, ',');
    std::getline(ss, r_mm, ',');
    std::getline(ss, uz, ',');
    if (layer != "0") continue;
    // At the needle edge r = a the skin surface rises after breakthrough.
    if (std::abs(std::stod(r_mm) - 0.635) < 1e-6) {
      if (phase == "before") uz_axis_before = std::stod(uz), ++before;
      if (phase == "after") uz_axis_after = std::stod(uz), ++after;
    }
  }
  EXPECT_EQ(before, 1);
  EXPECT_EQ(after, 1);
  EXPECT_GT(uz_axis_after, uz_axis_before);
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    EXPECT_NE(e.path().extension(), ".part") << e.path();
    EXPECT_EQ(e.path().filename().string().find(".staging-"), std::string::npos) << e.path();
  }
}

TEST(NeedleInsertion, HardCaseThinSkinNearlyIncompressibleDeepIndentationStaysFinite) {
  // Thin skin (0.8 mm) on thick muscle, nu = 0.499, indentation to 2.5 mm
  // (three skin thicknesses) without puncture: converges (cutting steps if
  // needed) with finite, increasing forces.
  Scene s;
  s.name = "hard_case";
  s.sample.diameter_m = 0.016;
  s.layers = {make_layer("skin", 0.8e-3, 1e5, 0.499, 1e9), make_layer("muscle", 8e-3, 1e4, 0.499, 1e9)};
  s.insertion.start_height_m = 0.0;
  s.insertion.target_depth_m = 2.5e-3;
  s.fem.load_step_m = 0.5e-3;
  const FemRunSummary r = run_needle_insertion(s, quiet_options(""), MPI_COMM_WORLD);
  ASSERT_FALSE(r.force_N.empty());
  EXPECT_NEAR(r.depth_m.back(), 2.5e-3, 1e-12);
  for (std::size_t i = 1; i < r.force_N.size(); ++i) {
    ASSERT_TRUE(std::isfinite(r.force_N[i]));
    EXPECT_GT(r.force_N[i], r.force_N[i - 1]);
  }
  EXPECT_TRUE(r.punctures.empty());
}

TEST(NeedleInsertion, TheAxisymmetricReferenceRefusesAnInclinedNeedle) {
  Scene s = small_three_layer_scene();
  s.needle.tip = "bevel";
  s.fem.geometry = "axisymmetric";
  s.insertion.angle_deg = 10.0;
  try {
    run_needle_insertion(s, quiet_options(""), MPI_COMM_WORLD);
    FAIL() << "an inclined needle was accepted by the axisymmetric reference";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("angle_deg"), std::string::npos) << e.what();
  }
}

namespace {

/// The rows of a fem_force_depth.csv: column name -> values.
std::map<std::string, std::vector<double>> read_force_depth_csv(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::vector<std::string> names;
  std::map<std::string, std::vector<double>> columns;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::stringstream fields(line);
    std::string field;
    if (names.empty()) {
      while (std::getline(fields, field, ',')) names.push_back(field);
      continue;
    }
    for (std::size_t i = 0; std::getline(fields, field, ',') && i < names.size(); ++i)
      if (!field.empty() && (std::isdigit(static_cast<unsigned char>(field[0])) || field[0] == '-'))
        columns[names[i]].push_back(std::stod(field));
  }
  return columns;
}

/// A blunt punch pressed along its path at `angle_deg` and `azimuth_deg` into
/// one thick nearly incompressible layer, from a start where its face (square
/// to the needle, reaching a sin a below its centre) is 0.05 a above the
/// surface, to a vertical depth of 0.3 a: the force-depth CSV's columns.
std::map<std::string, std::vector<double>> inclined_punch(double angle_deg, double azimuth_deg, const std::string& name) {
  Scene s;
  s.name = name;
  const double a = 0.635e-3, E = 1e4, nu = 0.499, h = 20 * a;
  s.sample.diameter_m = 32 * a;
  s.layers = {make_layer("top", 0.5e-3, E, nu, 1e9), make_layer("bulk", h - 0.5e-3, E, nu, 1e9)};
  s.needle.radius_m = a;
  s.insertion.angle_deg = angle_deg;
  s.insertion.azimuth_deg = azimuth_deg;
  const double angle = angle_deg * M_PI / 180.0;
  s.insertion.start_height_m = a * std::sin(angle) + 0.05 * a;
  s.insertion.target_depth_m = 0.3 * a;
  s.fem.load_step_m = 0.05 * a;
  const auto dir = fresh_dir(name);
  FemRunOptions o = quiet_options(dir.string());
  o.mesh.sectors = 12;
  o.mesh.radial_grading = 1.3;
  o.mesh.elements_through_skin = 2;
  o.mesh.thickness_grading = 1.3;
  const FemRunSummary r = run_needle_insertion(s, o, MPI_COMM_WORLD);
  EXPECT_TRUE(r.punctures.empty());
  return read_force_depth_csv(dir / "fem_force_depth.csv");
}

}  // namespace

// The blunt punch along an inclined path (meshing/inclined_path_mesh.hpp:
// the needle column follows it). Its face, square to the needle, meets the
// level surface with its lowest point first: the point of the column's rim
// at horizontal distance a / cos a behind the entry point along the tilt,
// whose coordinate along the needle is -a tan a, so the needle feels force
// from a path depth of -a tan a (a vertical depth of -a sin a) on, where
// along the sample axis it feels none before 0. The force then has a part
// across the needle. The run turned by 90 deg about the sample axis (whose
// O-grid mesh the turn maps onto itself) gives the same forces.
TEST(NeedleInsertion, InclinedBluntPunchMeetsTheSurfaceWithItsLowestPointFirst) {
  const double a = 0.635e-3, angle = 30.0, c = std::cos(angle * M_PI / 180.0), t = std::tan(angle * M_PI / 180.0);
  auto axial = inclined_punch(0.0, 0.0, "punch_0deg");
  auto inclined = inclined_punch(angle, 0.0, "punch_30deg");
  auto turned = inclined_punch(angle, 90.0, "punch_30deg_turned");
  ASSERT_FALSE(axial.count("lateral_force_N")) << "the axial run's CSV has no columns of an inclined needle";
  ASSERT_TRUE(inclined.count("lateral_force_N") && inclined.count("path_depth_mm"));
  const std::vector<double>& depth = inclined.at("depth_mm");
  const std::vector<double>& path = inclined.at("path_depth_mm");
  const std::vector<double>& force = inclined.at("force_N");
  const std::vector<double>& lateral = inclined.at("lateral_force_N");
  ASSERT_GT(depth.size(), 5u);
  // The first row with a force lies within a load step (0.05 a vertical) past -a tan a along the needle.
  std::size_t first = 0;
  while (first < force.size() && force[first] == 0.0) ++first;
  ASSERT_LT(first, force.size());
  ASSERT_GT(first, 0u) << "the start touched the surface";
  EXPECT_GE(path[first] * 1e-3, -a * t - 1e-9);
  EXPECT_LE(path[first - 1] * 1e-3, -a * t + 1e-9);
  EXPECT_LE(path[first] * 1e-3, -a * t + 0.05 * a / c + 1e-9);
  for (std::size_t i = 0; i < depth.size(); ++i) EXPECT_NEAR(path[i], depth[i] / c, 1e-9);
  for (std::size_t i = 0; i < axial.at("depth_mm").size(); ++i)
    if (axial.at("depth_mm")[i] < 0.0) EXPECT_EQ(axial.at("force_N")[i], 0.0);
  // Pressed: axial and lateral forces positive, the lateral one a fraction of the axial.
  EXPECT_GT(force.back(), 0.0);
  EXPECT_GT(lateral.back(), 0.0);
  EXPECT_LT(lateral.back(), force.back());
  // Turned by 90 deg: the same forces.
  ASSERT_EQ(turned.at("force_N").size(), force.size());
  for (std::size_t i = 0; i < force.size(); ++i) {
    EXPECT_NEAR(turned.at("force_N")[i], force[i], 1e-6 * force.back()) << "row " << i;
    EXPECT_NEAR(turned.at("lateral_force_N")[i], lateral[i], 1e-6 * force.back()) << "row " << i;
  }
  RecordProperty("lateral_over_axial", ::testing::PrintToString(lateral.back() / force.back()));
}

TEST(NeedleInsertion, CriticalStretchCriterionPuncturesWhenTheTipStretchIsReached) {
  Scene s = small_three_layer_scene();
  s.layers[0].puncture.kind = PunctureCriterion::Kind::CriticalStretch;
  s.layers[0].puncture.critical_stretch = 1.25;
  FemRunOptions o = quiet_options("");
  o.stop_depth_m = 1.5e-3;
  const FemRunSummary r = run_needle_insertion(s, o, MPI_COMM_WORLD);
  ASSERT_FALSE(r.punctures.empty());
  EXPECT_EQ(r.punctures[0].layer_name, "skin");
  EXPECT_GE(r.punctures[0].max_stretch, 1.25);
  EXPECT_GT(r.punctures[0].depth_m, 0.0);
  // Depth rows never go backwards and every force is finite.
  for (std::size_t i = 1; i < r.depth_m.size(); ++i) {
    EXPECT_GE(r.depth_m[i], r.depth_m[i - 1]);
    EXPECT_TRUE(std::isfinite(r.force_N[i]));
  }
}

TEST(NeedleInsertion, TheUnrefinedQ1MeshWarnsThatItIsTooStiff) {
  // results/fem_mesh_convergence.md: the 3D reference at Q1 without refinement
  // is about 10 % too stiff at small indentation; the run says so, in the
  // summary and in fem_summary.json. One uniform refinement gets no such warning.
  Scene s = small_three_layer_scene();
  s.insertion.start_height_m = 0.0;
  const auto dir = fresh_dir("coarse_warning");
  FemRunOptions o = quiet_options(dir.string());
  o.stop_depth_m = 0.25e-3;
  const FemRunSummary r = run_needle_insertion(s, o, MPI_COMM_WORLD);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("too stiff"), std::string::npos) << r.warnings[0];
  std::ifstream in(dir / "fem_summary.json");
  const auto summary = nlohmann::json::parse(in);
  ASSERT_EQ(summary.at("warnings").size(), 1u);
  o.refinement_override = 1;
  o.write_files = false;
  EXPECT_TRUE(run_needle_insertion(s, o, MPI_COMM_WORLD).warnings.empty());
  std::filesystem::remove_all(dir);
}

namespace {

/// The small slab, no punctures, every layer with one Prony term g = 0.5, tau = 0.05 s
/// on its long-term law (the scene's E and nu): instantaneously twice as stiff in shear.
Scene viscoelastic_slab(double speed_m_per_s) {
  Scene s = small_three_layer_scene();
  for (Layer& l : s.layers) {
    l.puncture.critical_force_N = 1e9;
    l.material.viscoelastic.terms = {{0.5, 0.05}};
    l.material.viscoelastic.modulus_basis = Viscoelasticity::ModulusBasis::LongTerm;
  }
  s.insertion.speed_m_per_s = speed_m_per_s;
  return s;
}

/// The same slab elastic, with the shear modulus times `shear_factor` and the bulk
/// modulus kept: E' = 9 K mu' / (3 K + mu'), nu' = (3 K - 2 mu') / (2 (3 K + mu')).
Scene elastic_slab(double shear_factor) {
  Scene s = viscoelastic_slab(0.01);
  for (Layer& l : s.layers) {
    const double E = l.material.youngs_modulus_Pa, nu = l.material.poisson_ratio;
    const double K = E / (3.0 * (1.0 - 2.0 * nu)), mu = shear_factor * E / (2.0 * (1.0 + nu));
    l.material.youngs_modulus_Pa = 9.0 * K * mu / (3.0 * K + mu);
    l.material.poisson_ratio = (3.0 * K - 2.0 * mu) / (2.0 * (3.0 * K + mu));
    l.material.viscoelastic.terms.clear();
  }
  return s;
}

double force_at_stop(const Scene& s) {
  FemRunOptions o = quiet_options("");
  o.stop_depth_m = 1.0e-3;
  const FemRunSummary r = run_needle_insertion(s, o, MPI_COMM_WORLD);
  EXPECT_NEAR(r.depth_m.back(), 1.0e-3, 1e-12);
  return r.force_N.back();
}

}  // namespace

TEST(NeedleInsertion, ViscoelasticLayersGoFromTheInstantaneousToTheLongTermLawWithTheSpeed) {
  // The 3D reference's Prony layers against two elastic runs that bound them: the
  // long-term law (the scene's) and the instantaneous one (shear modulus 1 / g_inf = 2
  // times, bulk kept). An insertion far faster than tau (1 mm in 0.1 ms) meets the
  // instantaneous law, one far slower (1 mm in 100 s = 2000 tau) the long-term law;
  // at 10 mm/s (1 mm in 2 tau) the force lies strictly between.
  const double long_term = force_at_stop(elastic_slab(1.0));
  const double instantaneous = force_at_stop(elastic_slab(2.0));
  ASSERT_GT(instantaneous, 1.5 * long_term);
  const double fast = force_at_stop(viscoelastic_slab(10.0)), slow = force_at_stop(viscoelastic_slab(1e-5));
  EXPECT_NEAR(fast / instantaneous, 1.0, 3e-3);
  EXPECT_NEAR(slow / long_term, 1.0, 1e-3);
  const double mid = force_at_stop(viscoelastic_slab(0.01));
  RecordProperty("fast_over_instantaneous", ::testing::PrintToString(fast / instantaneous));
  RecordProperty("slow_over_long_term", ::testing::PrintToString(slow / long_term));
  RecordProperty("mid_over_long_term", ::testing::PrintToString(mid / long_term));
  EXPECT_GT(mid, 1.05 * long_term);
  EXPECT_LT(mid, 0.95 * instantaneous);
}

TEST(NeedleInsertion, TheThreeDimensionalAndTheAxisymmetricReferenceAgreeOnABluntPunchAlongTheAxis) {
  // Two separate programs (hexahedra in 3D, the meridian plane) on one insertion that both
  // model: a flat punch along the axis of the layered slab (a stiff thin skin on soft fat),
  // Prony layers at 10 mm/s, no puncture, 1 mm deep. The unrefined 3D Q1 mesh is the stiffer
  // (results/fem_mesh_convergence.md); one uniform refinement must bring it to the
  // axisymmetric force (refined once too). Observed: 14.3 % above, then 3.2 %.
  Scene s = viscoelastic_slab(0.01);
  s.needle.tip = "blunt";
  FemRunOptions o = quiet_options("");
  o.mesh = meshing::SlabMeshOptions{};  // the default cross-section (16 sectors), not the tests' coarse one
  o.stop_depth_m = 1.0e-3;
  double force_3d[2] = {0.0, 0.0};
  for (int refinement : {0, 1}) {
    o.refinement_override = refinement;
    const FemRunSummary r = run_needle_insertion(s, o, MPI_COMM_WORLD);
    ASSERT_NEAR(r.depth_m.back(), 1.0e-3, 1e-12);
    force_3d[refinement] = r.force_N.back();
  }
  s.fem.geometry = "axisymmetric";
  o.refinement_override = 1;
  const FemRunSummary axi = run_needle_insertion(s, o, MPI_COMM_WORLD);
  ASSERT_NEAR(axi.depth_m.back(), 1.0e-3, 1e-12);
  const double f_axi = axi.force_N.back();
  RecordProperty("coarse_3d_over_axisymmetric", ::testing::PrintToString(force_3d[0] / f_axi));
  RecordProperty("refined_3d_over_axisymmetric", ::testing::PrintToString(force_3d[1] / f_axi));
  EXPECT_LT(std::abs(force_3d[1] - f_axi), std::abs(force_3d[0] - f_axi) / 3.0);
  EXPECT_NEAR(force_3d[1] / f_axi, 1.0, 0.04);
}
