// Raw rig recordings (validation/harness recording.hpp, raw_recording.cpp,
// recording_format.cpp): the format from a sidecar or the command line's
// fields, errors naming the file and the field, phases from the stage,
// contact and tare from the force on seeded synthetic recordings with known
// contact and tare, the shared rig-like recording (contact 4 mm after the
// start, offset 0.31 N, puncture at 14.74 mm from contact), and the simple
// depth_mm,force_N format read as before.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "puncture/validation/puncture_events.hpp"
#include "puncture/validation/recording.hpp"

namespace pv = puncture::validation;
namespace fs = std::filesystem;

namespace {

const fs::path kSharedData = PUNCTURE_SHARED_DATA_DIR;

pv::RecordingFormat rig_format() {
  pv::RecordingFormat f;
  f.source = "test format";
  f.time = {"t_us", ""};
  f.position = {"stage_mm", ""};
  f.force = {"Fz_N", ""};
  f.into_tissue = pv::StageDirection::Increasing;
  f.force_sign = 1;
  return f;
}

/// A synthetic rig recording: `approach_mm` of approach at `speed` mm/s, a
/// quadratic rise to 4 N at 10 mm from contact, a one-sample fall to 1.8 N,
/// a rise of 0.3 N/mm to `depth_mm`, a 2 s hold, withdrawal to the start.
/// direction -1: the stage position decreases into the tissue; sign -1: the
/// file's force is negative while pressing; units us, um, mN.
struct SyntheticRig {
  double approach_mm = 3.0, speed = 2.0, depth_mm = 16.0, tare_N = 0.25, sigma = 0.02, start_stage_mm = 50.0;
  int direction = 1, sign = 1;
  unsigned seed = 1;
};
double law(double z) {
  if (z <= 0.0) return 0.0;
  if (z <= 10.0 + 1e-9) return 4.0 * (z / 10.0) * (z / 10.0);
  return 1.8 + 0.3 * (z - 10.0);
}
std::string synthetic_csv(const SyntheticRig& r) {
  std::mt19937 rng(r.seed);
  std::normal_distribution<double> noise(0.0, r.sigma);
  std::ostringstream csv;
  csv.precision(10);
  csv << "# synthetic rig recording\ntime_us,position_um,load_mN,temperature_C\n";
  const double dt = 0.01, travel = r.approach_mm + r.depth_mm, t_in = travel / r.speed;
  for (double t = 0.0; t <= t_in + 2.0 + t_in + 1e-9; t += dt) {
    double s = t <= t_in ? r.speed * t : t <= t_in + 2.0 ? travel : travel - r.speed * (t - t_in - 2.0);
    const double z = s - r.approach_mm;
    double f = t <= t_in ? law(z) : t <= t_in + 2.0 ? law(r.depth_mm) * (0.7 + 0.3 * std::exp(-(t - t_in))) : 0.5 * law(z);
    f = r.tare_N + f + noise(rng);
    csv << std::llround(t * 1e6) << ',' << (r.start_stage_mm + r.direction * s) * 1e3 << ',' << r.sign * f * 1e3 << ",21\n";
  }
  return csv.str();
}
pv::RecordingFormat synthetic_format(const SyntheticRig& r) {
  pv::RecordingFormat f;
  f.source = "synthetic format";
  f.time = {"time_us", ""};
  f.position = {"position_um", ""};
  f.force = {"load_mN", ""};
  f.into_tissue = r.direction > 0 ? pv::StageDirection::Increasing : pv::StageDirection::Decreasing;
  f.force_sign = r.sign;
  return f;
}

pv::RawRecording convert(const std::string& csv, const pv::RecordingFormat& f, const std::string& name = "rig.csv") {
  return pv::curve_from_raw_recording(puncture::io::parse_csv(csv, name), f);
}

/// The message of the RecordingError (or CurveFormatError) that `body` throws.
template <class Body>
std::string error_of(Body&& body) {
  try {
    body();
  } catch (const pv::RecordingError& e) {
    return e.what();
  } catch (const pv::CurveFormatError& e) {
    return e.what();
  }
  return "no error";
}

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("puncture_test_recording_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

}  // namespace

TEST(RawRecording, ContactTareAndPhasesAreRecoveredOnSeededSyntheticRecordings) {
  // Sixteen members: both stage directions, both force signs, noise 0.005 to
  // 0.05 N, approaches of 2 to 5 mm, tares of -0.5 to 0.5 N.
  std::mt19937 draw(49);
  std::uniform_real_distribution<double> approach(2.0, 5.0), tare(-0.5, 0.5);
  const double sigmas[] = {0.005, 0.02, 0.05};
  for (int m = 0; m < 16; ++m) {
    SyntheticRig r;
    r.approach_mm = approach(draw), r.tare_N = tare(draw), r.sigma = sigmas[m % 3];
    r.direction = m % 2 ? -1 : 1, r.sign = (m / 2) % 2 ? -1 : 1, r.seed = 100 + static_cast<unsigned>(m);
    const std::string what = "member " + std::to_string(m);
    const pv::RawRecording raw = convert(synthetic_csv(r), synthetic_format(r));
    const pv::InsertionCurve& c = raw.curve;
    // Contact: the stage position at the true contact, within 0.02 mm + 2 mm
    // per N of noise (the rise leaves the noise later the noisier it is: 0.03,
    // 0.06 and 0.12 mm at 0.005, 0.02 and 0.05 N).
    const double tol = 0.02 + 2.0 * r.sigma;  // mm
    const double contact_um = (r.start_stage_mm + r.direction * r.approach_mm) * 1e3;  // the file's unit
    EXPECT_NEAR(raw.analysis.contact_stage, contact_um, tol * 1e3) << what;
    EXPECT_NEAR(raw.analysis.contact_time_s, r.approach_mm / r.speed, tol / r.speed) << what;
    EXPECT_NEAR(raw.analysis.tare_N, r.tare_N, 3.0 * r.sigma / std::sqrt(12.0) + 0.005) << what;
    EXPECT_NEAR(raw.analysis.noise_N, r.sigma, 0.2 * r.sigma) << what;
    EXPECT_NEAR(raw.analysis.insertion_speed_m_per_s, r.speed * 1e-3, 1e-9) << what;
    EXPECT_NEAR(raw.analysis.withdrawal_speed_m_per_s, r.speed * 1e-3, 1e-9) << what;
    // Phases: the insertion to the deepest sample, a 2 s hold, the withdrawal.
    const std::vector<std::size_t> in = pv::insertion_phase(c), hold = pv::dwell_phase(c), out = pv::withdrawal_phase(c);
    EXPECT_NEAR(c.depth_m[in.back()] * 1e3, r.depth_mm, tol) << what;
    EXPECT_NEAR(c.depth_m[in.front()] * 1e3, -r.approach_mm, tol) << what;
    ASSERT_GE(hold.size(), 2u) << what;
    EXPECT_NEAR(c.time_s[hold.back()] - c.time_s[in.back()], 2.0, 0.011) << what;
    EXPECT_NEAR(c.depth_m[out.back()] * 1e3, -r.approach_mm, tol) << what;
    double v = 0.0;
    ASSERT_TRUE(c.metadata_number("speed_mm_per_s", v)) << what;
    EXPECT_NEAR(v, r.speed, 1e-6) << what;
    // Tared and in N, positive while pressing: 4 N at 10 mm from contact.
    std::size_t at8 = in.front();
    for (std::size_t i : in)
      if (std::abs(c.depth_m[i] - 8e-3) < std::abs(c.depth_m[at8] - 8e-3)) at8 = i;
    EXPECT_NEAR(c.force_N[at8], law(c.depth_m[at8] * 1e3), 5.0 * r.sigma + 0.64 * tol) << what;  // 0.64 N/mm at 8 mm
    // The puncture at 10 mm from contact.
    const std::vector<pv::ForceDrop> drops = pv::detect_force_drops(c);
    ASSERT_EQ(drops.size(), 1u) << what;
    EXPECT_NEAR(drops[0].depth_m * 1e3, 10.0 + 0.01, tol + 0.01) << what;  // the sample after 10 mm
  }
}

TEST(RawRecording, SharedRigLikeRecordingHasItsPunctureAt14Point74MmFromContact) {
  const fs::path path = kSharedData / "rig_like_recording.csv";
  ASSERT_TRUE(fs::exists(path)) << path << " is missing: the tests need shared/data beside the repository clone";
  pv::ReferenceRecordingOptions o;
  o.overrides = rig_format();
  const pv::InsertionCurve c = pv::read_reference_recording(path, o);
  // Its header: contact 4 mm after the start (stage 37.5 mm), offset 0.31 N,
  // noise 0.02 N, 2 mm/s, a 5 s hold, withdrawal to 4 mm above the surface.
  double contact = 0.0, tare = 0.0, noise = 0.0, speed = 0.0;
  ASSERT_TRUE(c.metadata_number("contact_stage_mm", contact));
  ASSERT_TRUE(c.metadata_number("tare_N", tare));
  ASSERT_TRUE(c.metadata_number("noise_N", noise));
  ASSERT_TRUE(c.metadata_number("speed_mm_per_s", speed));
  EXPECT_NEAR(contact, 41.5, 0.05);
  EXPECT_NEAR(tare, 0.31, 0.01);
  EXPECT_NEAR(noise, 0.02, 0.004);
  EXPECT_NEAR(speed, 2.0, 1e-6);
  const std::vector<std::size_t> hold = pv::dwell_phase(c), out = pv::withdrawal_phase(c);
  ASSERT_FALSE(hold.empty());
  EXPECT_NEAR(c.time_s[hold.back()] - c.time_s[hold.front()], 5.0, 0.05);
  EXPECT_NEAR(c.depth_m[out.back()] * 1e3, -4.0, 0.1);
  const std::vector<pv::ForceDrop> drops = pv::detect_force_drops(c);
  ASSERT_EQ(drops.size(), 1u);
  EXPECT_NEAR(drops[0].depth_m * 1e3, 14.74, 0.1);
  EXPECT_FALSE(drops[0].marginal);
  // From the highest sample within the window before the fall (the sag's
  // upper part) to the fall's lowest: at least the fall itself.
  EXPECT_GT(drops[0].drop_N, 4.57 - 2.26 - 0.1);
  EXPECT_LT(drops[0].drop_N, 5.0 - 2.26 + 0.1);
  // A two-layer geometry (skin on muscle, passing only the skin's bottom): no doubt.
  const std::vector<pv::LayerGeometry> skin_on_muscle{{"skin", 0.0, 2e-3, 1e-3}, {"muscle", 2e-3, 40e-3, 1e-3}};
  const pv::ReferenceEvents ev = pv::reference_events(c, skin_on_muscle);
  EXPECT_TRUE(ev.doubts.empty()) << ev.doubts.front();
  ASSERT_TRUE(ev.punctures[0].found);
  EXPECT_NEAR(ev.punctures[0].depth_m * 1e3, 14.74, 0.1);
}

TEST(RawRecording, SidecarBesideTheCsvIsFoundAndTheCommandLineWinsFieldByField) {
  const fs::path dir = scratch("sidecar");
  SyntheticRig r;
  r.sign = -1;
  std::ofstream(dir / "bench.csv") << synthetic_csv(r);
  // The sidecar says sign +1 (wrong): the force never leaves the noise upwards.
  std::ofstream(dir / "bench.json") << R"({ "description": "bench 3",
    "time": { "column": "time_us" }, "position": { "column": "position_um", "into_tissue": "increasing" },
    "force": { "column": "load_mN", "unit": "mN", "sign": 1 } })";
  const std::string wrong = error_of([&] { pv::read_reference_recording(dir / "bench.csv"); });
  EXPECT_EQ(wrong.rfind((dir / "bench.csv").string() + ": ", 0), 0u) << wrong;
  EXPECT_NE(wrong.find("never leaves the noise"), std::string::npos) << wrong;
  EXPECT_NE(wrong.find("force.sign"), std::string::npos) << wrong;
  pv::ReferenceRecordingOptions o;
  o.overrides.force_sign = -1;
  o.overrides.source = "the command line";
  const pv::InsertionCurve c = pv::read_reference_recording(dir / "bench.csv", o);
  EXPECT_NE(c.metadata.at("recording_format").find("bench.json and the command line"), std::string::npos);
  EXPECT_FALSE(c.content_hash.empty());
  ASSERT_EQ(pv::detect_force_drops(c).size(), 1u);
  // --recording-format: another file than the sidecar.
  std::ofstream(dir / "other.json") << R"({ "time": { "column": "time_us", "unit": "us" },
    "position": { "column": "position_um", "unit": "um", "into_tissue": "increasing" },
    "force": { "column": "load_mN", "unit": "mN", "sign": -1 } })";
  o = {};
  o.format_file = dir / "other.json";
  EXPECT_EQ(pv::read_reference_recording(dir / "bench.csv", o).force_N, c.force_N);
  fs::remove_all(dir);
}

TEST(RawRecording, FormatErrorsNameTheFileAndTheField) {
  const auto parse_error = [](const std::string& json) {
    return error_of([&] { pv::check_recording_format(pv::parse_recording_format(json, "rig.json")); });
  };
  const std::string complete_time = R"("time": {"column": "t_us"}, )";
  const std::string complete_force = R"(, "force": {"column": "Fz_N", "sign": 1})";
  const std::pair<std::string, std::string> cases[] = {
      {"{", "not valid JSON"},
      {"[1]", "must be a JSON object"},
      {R"({"speed": 2})", "field 'speed': unknown key"},
      {"{" + complete_time + R"("position": {"column": "s_mm", "speed": 1})" + complete_force + "}",
       "field 'position.speed': unknown key"},
      {"{" + complete_time + R"("position": {"column": "s_mm", "into_tissue": "down"})" + complete_force + "}",
       "field 'position.into_tissue': must be \"increasing\" or \"decreasing\""},
      {"{" + complete_time + R"("position": {"column": "s_mm"})" + complete_force + "}",
       "field 'position.into_tissue': missing"},
      {"{" + complete_time + R"("position": {"column": "s_mm", "into_tissue": "increasing"}, "force": {"column": "F_N"}})",
       "field 'force.sign': missing"},
      {"{" + complete_time + R"("position": {"column": "s_mm", "into_tissue": "increasing"}, "force": {"column": "F_N", "sign": 2}})",
       "field 'force.sign': must be 1 or -1"},
      {R"({"time": {"column": "t"}, "position": {"column": "s_mm", "into_tissue": "increasing"})" + complete_force + "}",
       "field 'time.unit': missing, and the column name 't' does not end in a known unit"},
      {R"({"time": {"column": "t", "unit": "h"}, "position": {"column": "s_mm", "into_tissue": "increasing"})" +
           complete_force + "}",
       "field 'time.unit': unknown time unit 'h'"},
      {R"({"position": {"column": "s_mm", "into_tissue": "increasing"})" + complete_force + "}",
       "field 'time.column': missing"},
  };
  for (const auto& [json, expected] : cases) {
    const std::string e = parse_error(json);
    EXPECT_EQ(e.rfind("rig.json: ", 0), 0u) << e;
    EXPECT_NE(e.find(expected), std::string::npos) << json << "\n" << e;
  }
}

TEST(RawRecording, RecordingsThatCannotBeReadAreClearErrors) {
  SyntheticRig r;
  const pv::RecordingFormat f = synthetic_format(r);
  // A column the format names is not in the header.
  pv::RecordingFormat missing = f;
  missing.force.name = "Fz_mN";
  const std::string no_column = error_of([&] { convert(synthetic_csv(r), missing); });
  EXPECT_EQ(no_column.rfind("rig.csv: ", 0), 0u) << no_column;
  EXPECT_NE(no_column.find("column 'Fz_mN' (force.column of synthetic format) is not in the header"), std::string::npos)
      << no_column;
  // The stage does not move.
  std::ostringstream still;
  still << "time_us,position_um,load_mN\n";
  for (int i = 0; i < 200; ++i) still << i * 10000 << ",5000," << 300 + 100 * (i > 100) << '\n';
  const std::string no_motion = error_of([&] { convert(still.str(), f); });
  EXPECT_NE(no_motion.find("rig.csv: the stage does not move: column 'position_um' spans "), std::string::npos)
      << no_motion;
  // The force never leaves the noise.
  std::ostringstream quiet;
  {
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 20.0);  // mN
    quiet << "time_us,position_um,load_mN\n";
    for (int i = 0; i < 1000; ++i) quiet << i * 10000 << ',' << 20.0 * i << ',' << 250 + noise(rng) << '\n';
  }
  const std::string in_noise = error_of([&] { convert(quiet.str(), f); });
  EXPECT_NE(in_noise.find("rig.csv: the force never leaves the noise"), std::string::npos) << in_noise;
  // The recording starts in contact: nothing to tare from.
  SyntheticRig touching = r;
  touching.approach_mm = 0.0;
  const std::string in_contact = error_of([&] { convert(synthetic_csv(touching), f); });
  EXPECT_NE(in_contact.find("rig.csv: the recording starts in contact"), std::string::npos) << in_contact;
  // Time that does not increase, and a value that is no number: file, line, column.
  std::string back = synthetic_csv(r);
  back.replace(back.find("\n20000,"), 7, "\n00000,");
  const std::string time_error = error_of([&] { convert(back, f); });
  EXPECT_NE(time_error.find("rig.csv:5: column 'time_us': time must increase"), std::string::npos) << time_error;
  std::string word = synthetic_csv(r);
  const std::size_t row = word.find("\n30000,");
  word.replace(word.find(',', row + 1) + 1, 0, "x");
  const std::string nan_error = error_of([&] { convert(word, f); });
  EXPECT_NE(nan_error.find("rig.csv:6: column 'position_um': not a finite number"), std::string::npos) << nan_error;
  // A stage that moves back during the insertion.
  std::ostringstream twice;
  twice << "time_us,position_um,load_mN\n";
  for (int i = 0; i < 400; ++i) twice << i * 10000 << ',' << 20.0 * (i < 200 ? i : 400 - i) + 30.0 * (i >= 300) * (i - 300) << ",300\n";
  const std::string back_and_forth = error_of([&] { convert(twice.str(), f); });
  EXPECT_NE(back_and_forth.find("one insertion per file"), std::string::npos) << back_and_forth;
}

TEST(RawRecording, TheSimpleDepthForceFormatReadsAsBefore) {
  const fs::path dir = scratch("simple");
  const std::string text = "# speed_mm_per_s: 2\ndepth_mm,force_N\n0,0\n1,0.5\n2,1.0\n2.02,0.4\n3,0.6\n";
  std::ofstream(dir / "curve.csv") << text;
  const pv::InsertionCurve via_recording = pv::read_reference_recording(dir / "curve.csv");
  const pv::InsertionCurve direct = pv::read_insertion_curve(dir / "curve.csv");
  EXPECT_EQ(via_recording.depth_m, direct.depth_m);
  EXPECT_EQ(via_recording.force_N, direct.force_N);
  EXPECT_EQ(via_recording.metadata, direct.metadata);
  EXPECT_EQ(via_recording.content_hash, direct.content_hash);
  EXPECT_EQ(pv::parse_insertion_curve(text, "curve.csv").force_N, direct.force_N);
  // A raw recording without a format: the error says how to give one.
  std::ofstream(dir / "raw.csv") << "t_us,stage_mm,Fz_N\n0,1,0.3\n";
  const std::string e = error_of([&] { pv::read_reference_recording(dir / "raw.csv"); });
  EXPECT_NE(e.find("column 'depth_mm': required column missing"), std::string::npos) << e;
  EXPECT_NE(e.find("raw.json"), std::string::npos) << e;
  EXPECT_NE(e.find("--recording-format"), std::string::npos) << e;
  fs::remove_all(dir);
}
