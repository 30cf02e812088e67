// Puncture detection on measured-style (noisy) depth-force curves: synthetic
// curves with known drops and seeded Gaussian noise, the shared noisy example
// and the shared Okamura et al. 2004 liver curve (shared/data beside the
// clone: PUNCTURE_SHARED_DATA_DIR); what the detection doubts; what a
// reference that cannot be fitted gives.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <sstream>

#include "puncture/scene_io.hpp"
#include "puncture/validation/calibration.hpp"
#include "puncture/validation/force_noise.hpp"
#include "puncture/validation/puncture_events.hpp"
#include "puncture/validation/reference_checks.hpp"
#include "puncture/validation/recording.hpp"

namespace pv = puncture::validation;
namespace fs = std::filesystem;

namespace {

const fs::path kSharedData = PUNCTURE_SHARED_DATA_DIR;

pv::InsertionCurve shared_curve(const std::string& name) {
  const fs::path path = kSharedData / name;
  if (!fs::exists(path))
    throw std::runtime_error("shared data file " + path.string() +
                             " is missing: the tests need shared/data beside the repository clone");
  return pv::read_insertion_curve(path);
}

/// The shared example's law (its header): F = 0.05 z + 0.02 z^2 (z in mm) up to
/// 14.2 mm, flat to 14.6 mm, a 55 % fall over 0.2 mm, then 0.45 F_peak + 0.12 N/mm.
/// With `early_drop`: also a 50 % fall over 0.2 mm at 6 mm, after which the
/// force rises again with the same law from the lower level.
double known_force(double z, bool early_drop) {
  auto rise = [](double x) { return 0.05 * x + 0.02 * x * x; };
  double offset = 0.0;
  if (early_drop && z > 6.0) offset = -0.5 * rise(6.0) * std::min(1.0, (z - 6.0) / 0.2);
  const double peak = rise(14.2) + (early_drop ? -0.5 * rise(6.0) : 0.0);
  if (z <= 14.2) return rise(z) + offset;
  if (z <= 14.6) return peak;
  if (z <= 14.8) return peak * (1.0 - 0.55 * (z - 14.6) / 0.2);
  return 0.45 * peak + 0.12 * (z - 14.8);
}

/// 0..20 mm every 0.02 mm; drops: 0 (a plain rise), 1 or 2.
pv::InsertionCurve noisy_curve(int drops, double sigma_N, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma_N);
  std::ostringstream csv;
  csv << "# speed_mm_per_s: 2\ndepth_mm,force_N\n";
  csv.precision(10);
  for (int i = 0; i <= 1000; ++i) {
    const double z = 0.02 * i;
    const double f = drops == 0 ? 0.05 * z + 0.02 * z * z : known_force(z, drops == 2);
    csv << z << ',' << f + noise(rng) << '\n';
  }
  return pv::parse_insertion_curve(csv.str(), "noisy_" + std::to_string(drops) + ".csv");
}

}  // namespace

TEST(NoisyDrops, NoiseIsEstimatedFromTheCurveItself) {
  for (double sigma : {0.01, 0.03, 0.05}) {
    const pv::InsertionCurve c = noisy_curve(1, sigma, 7);
    EXPECT_NEAR(pv::force_noise_sigma_N(c, pv::insertion_phase(c)), sigma, 0.15 * sigma) << sigma;
  }
  const pv::InsertionCurve smooth = noisy_curve(1, 0.0, 7);
  EXPECT_LT(pv::force_noise_sigma_N(smooth, pv::insertion_phase(smooth)), 1e-9);
}

TEST(NoisyDrops, KnownDropsAreFoundOnceEachAtEveryNoiseLevelAndSeed) {
  for (double sigma : {0.01, 0.03, 0.05})
    for (unsigned seed : {1u, 2u, 3u, 4u}) {
      const std::string what = "sigma " + std::to_string(sigma) + " seed " + std::to_string(seed);
      EXPECT_TRUE(pv::detect_force_drops(noisy_curve(0, sigma, seed)).empty()) << what;
      const std::vector<pv::ForceDrop> one = pv::detect_force_drops(noisy_curve(1, sigma, seed));
      ASSERT_EQ(one.size(), 1u) << what;
      EXPECT_GE(one[0].depth_m, 14.6e-3 - 1e-9) << what;
      EXPECT_LE(one[0].depth_m, 14.8e-3 + 1e-9) << what;
      EXPECT_FALSE(one[0].marginal) << what;
      EXPECT_NEAR(one[0].drop_N, 0.55 * known_force(14.4, false), 6.0 * sigma) << what;
      const std::vector<pv::ForceDrop> two = pv::detect_force_drops(noisy_curve(2, sigma, seed));
      ASSERT_EQ(two.size(), 2u) << what;
      EXPECT_GE(two[0].depth_m, 6.0e-3 - 1e-9) << what;
      EXPECT_LE(two[0].depth_m, 6.2e-3 + 1e-9) << what;
      EXPECT_GE(two[1].depth_m, 14.6e-3 - 1e-9) << what;
      EXPECT_LE(two[1].depth_m, 14.8e-3 + 1e-9) << what;
    }
}

TEST(NoisyDrops, SharedNoisyExampleHasItsOneDropAt14Point6To14Point8Mm) {
  const pv::InsertionCurve c = shared_curve("noisy_drop_example.csv");
  const std::vector<pv::ForceDrop> drops = pv::detect_force_drops(c);
  ASSERT_EQ(drops.size(), 1u);
  EXPECT_GE(drops[0].depth_m, 14.6e-3 - 1e-9);
  EXPECT_LE(drops[0].depth_m, 14.8e-3 + 1e-9);
  EXPECT_GT(drops[0].drop_N, 2.3);  // 55 % of 4.7 N
}

TEST(NoisyDrops, OkamuraLiverCurveHasTheDropsOneSees) {
  // Plotted, the curve is flat (noise) to about 9.5 mm, rises to 1.37 N and
  // falls to 0.15-0.4 N at 19.1 mm (the capsule), then shows clear falls at
  // 29.9 mm (1.7 -> 0.7 N), 32.75 mm (1.96 -> 1.0 N), 35.25 mm (1.55 ->
  // 1.34 N) and 36.7 mm (2.3 -> 1.3 N), a small one at 37.16 mm (1.52 ->
  // 1.34 N, 12.6 sigma, after a rise of 0.22 N from 1.30 N), and relaxes
  // flat beyond 38 mm. (Until issue 49 the fall at 37.16 mm was not counted:
  // the force rises more steeply after it than before, which the old rule,
  // a stiff rise giving way to a softer course, rejected; a drop followed by
  // a stiffer course now counts, as several drops in one layer do.)
  const pv::InsertionCurve c = shared_curve("okamura2004_liver_depth_force.csv");
  const std::vector<pv::ForceDrop> drops = pv::detect_force_drops(c);
  std::vector<double> clear;
  for (const pv::ForceDrop& d : drops) {
    EXPECT_GT(d.depth_m, 15e-3) << "a drop before contact at " << d.depth_m * 1e3 << " mm";
    EXPECT_LT(d.depth_m, 38e-3) << "a drop in the flat tail at " << d.depth_m * 1e3 << " mm";
    if (!d.marginal) clear.push_back(d.depth_m * 1e3);
  }
  const double seen[][2] = {{19.0, 19.35}, {29.8, 30.15}, {32.6, 32.9}, {35.1, 35.4}, {36.5, 36.85}, {37.0, 37.3}};
  std::string found;
  for (double d : clear) found += std::to_string(d) + " mm ";
  ASSERT_EQ(clear.size(), 6u) << found;
  for (std::size_t k = 0; k < 6; ++k) {
    EXPECT_GE(clear[k], seen[k][0]) << k;
    EXPECT_LE(clear[k], seen[k][1]) << k;
  }
}

TEST(NoisyDrops, DetectionDoubtsAreListed) {
  const std::vector<pv::LayerGeometry> one_layer{{"skin", 0.0, 30e-3, 1e-3}};
  const std::vector<pv::LayerGeometry> three_thin{{"a", 0.0, 1e-3, 1e-3}, {"b", 1e-3, 1e-3, 1e-3}, {"c", 2e-3, 1e-3, 1e-3}};
  // One clear drop, one layer not passed: no doubt.
  EXPECT_TRUE(pv::reference_events(noisy_curve(1, 0.03, 5), one_layer).doubts.empty());
  // Two clear drops for one layer.
  const pv::ReferenceEvents two = pv::reference_events(noisy_curve(2, 0.03, 5), one_layer);
  ASSERT_EQ(two.doubts.size(), 1u);
  EXPECT_NE(two.doubts[0].find("2 clear force drops for 1 layers"), std::string::npos) << two.doubts[0];
  // One drop, but the curve passes the bottom of three layers.
  const pv::ReferenceEvents passed = pv::reference_events(noisy_curve(1, 0.03, 5), three_thin);
  ASSERT_EQ(passed.doubts.size(), 1u);
  EXPECT_NE(passed.doubts[0].find("passes the undeformed bottom of 3 layer(s)"), std::string::npos);
  // A drop of about 10 sigma on a plain rise is marginal.
  pv::InsertionCurve marginal = noisy_curve(0, 0.03, 5);
  for (std::size_t i = 0; i < marginal.size(); ++i)
    if (marginal.depth_m[i] > 5.01e-3) marginal.force_N[i] -= 0.24;
  const pv::ReferenceEvents m = pv::reference_events(marginal, one_layer);
  ASSERT_EQ(m.drops.size(), 1u);
  EXPECT_TRUE(m.drops[0].marginal) << m.drops[0].noise_sigmas;
  ASSERT_EQ(m.doubts.size(), 1u);
  EXPECT_NE(m.doubts[0].find("x the noise"), std::string::npos) << m.doubts[0];
}

namespace {
puncture::Scene default_slab() { return puncture::load_scene(fs::path(PUNCTURE_SOURCE_DIR) / "scenes" / "default_force_law.json"); }

std::string calibrate_error(const pv::InsertionCurve& reference, const std::vector<double>& depths_m = {}) {
  pv::CalibrationOptions o;
  o.puncture_depths_m = depths_m;
  try {
    pv::calibrate(default_slab(), reference, o);
  } catch (const pv::ReferenceError& e) {
    return e.what();
  }
  return "no ReferenceError";
}
}  // namespace

TEST(UnfittableReference, IsAnErrorNamingTheFileAndWhy) {
  const std::string one_row = calibrate_error(pv::parse_insertion_curve("depth_mm,force_N\n0,0\n", "one_row.csv"));
  EXPECT_EQ(one_row.rfind("one_row.csv: ", 0), 0u) << one_row;
  EXPECT_NE(one_row.find("no force above the noise"), std::string::npos) << one_row;
  const std::string last = calibrate_error(pv::parse_insertion_curve("depth_mm,force_N\n0,0\n1,0\n2,0\n3,1\n", "last.csv"));
  EXPECT_EQ(last.rfind("last.csv: ", 0), 0u) << last;
  EXPECT_NE(last.find("no samples after contact"), std::string::npos) << last;
  // The skin pressed by four samples and punctured: K, a2, a3 and its critical
  // force for three samples after the contact.
  const std::string few = calibrate_error(
      pv::parse_insertion_curve("depth_mm,force_N\n0,0\n0.5,0.2\n1.0,0.4\n1.5,0.6\n1.6,0.2\n", "few.csv"));
  EXPECT_EQ(few.rfind("few.csv: ", 0), 0u) << few;
  EXPECT_NE(few.find("fewer samples after contact (3) than tuned parameters (4)"), std::string::npos) << few;
  // Three rows inside the skin, no drop: two pressing samples identify nothing.
  const std::string three = calibrate_error(
      pv::parse_insertion_curve("depth_mm,force_N\n0,0\n0.2,0.1\n0.4,0.2\n", "three.csv"));
  EXPECT_NE(three.find("three.csv: "), std::string::npos) << three;
  EXPECT_NE(three.find("identifies no parameter"), std::string::npos) << three;
}

TEST(UnfittableReference, FiveRowsWithOneDropTuneOnlyTheSkinsCriticalForce) {
  // The drop at 2 mm after 2 N identifies the skin's critical force (the
  // puncture's force sets it); two pressing samples and a one-sample cut
  // identify nothing else, and nothing of the fat and muscle: each of those
  // parameters keeps its start value with a warning.
  pv::CalibrationOptions o;
  const puncture::Scene scene = default_slab();
  const pv::CalibrationResult r = pv::calibrate(
      scene, pv::parse_insertion_curve("depth_mm,force_N\n0,0\n1,1\n2,2\n2.5,0.5\n3,0.6\n", "five.csv"), o);
  ASSERT_EQ(r.parameters.size(), 1u);
  EXPECT_EQ(r.parameters[0].layer, "skin");
  EXPECT_EQ(r.parameters[0].name, "critical_force");
  // Moved from its start (2.75 N) toward the drop's 2 N; K stays at its start,
  // so the fit trades the puncture's force against its depth.
  EXPECT_LT(r.parameters[0].tuned, r.parameters[0].start - 0.1);
  EXPECT_NEAR(r.parameters[0].tuned, 2.0, 0.6);
  std::size_t kept = 0;
  for (const std::string& w : r.warnings) kept += w.find("kept at its start value") != std::string::npos;
  EXPECT_GE(kept, 6u);  // the skin's K, stiffening, cutting, friction at least
  ASSERT_EQ(r.tuned.size(), scene.layers.size());
  EXPECT_EQ(r.tuned[1].critical_force_N, r.initial[1].critical_force_N);
}

TEST(UnfittableReference, UnsureDetectionAsksForPunctureDepths) {
  const pv::InsertionCurve noisy = shared_curve("noisy_drop_example.csv");
  const std::string e = calibrate_error(noisy);
  EXPECT_NE(e.find("noisy_drop_example.csv: "), std::string::npos) << e;
  EXPECT_NE(e.find("puncture detection is unsure"), std::string::npos) << e;
  EXPECT_NE(e.find("--puncture-depths"), std::string::npos) << e;
  const std::string liver = calibrate_error(shared_curve("okamura2004_liver_depth_force.csv"));
  EXPECT_NE(liver.find("clear force drops for 3 layers"), std::string::npos) << liver;
}
