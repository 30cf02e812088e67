// metrics.hpp: insertion curves (force against depth) and how far a model's
// curve lies from a reference curve.
//
// InsertionCurve: one sample per row, SI units inside. Read from a CSV file
// (recording.hpp: read_insertion_curve; a raw rig recording of time, stage
// position and force is converted by read_reference_recording) with one
// reader for the real-time model's realtime_curve.csv, the FEM's
// fem_force_depth.csv and a MEASURED insertion curve:
//   * optional metadata lines at the top, "# key: value" (e.g.
//     "# needle_gauge: 18", "# speed_mm_per_s: 10", "# source: ..."),
//     kept in InsertionCurve::metadata; other lines starting with '#' are
//     comments;
//   * a header line; required columns depth_mm and force_N; optional
//     columns time_s, velocity_mm_per_s, phase (insertion | dwell |
//     withdrawal), tip_force_N + cutting_force_N + friction_force_N (the
//     force's parts, all three or none), <layer>_state (untouched | pressed |
//     punctured); every other column is ignored (any order);
//   * one row per sample. Depth is the tip depth below the undeformed skin
//     surface (positive down), velocity > 0 while inserting, force > 0 when
//     it resists insertion (negative on withdrawal: friction reverses).
//   * Without a phase column the phase is inferred: samples up to the first
//     deepest one are the insertion; after it, a sample at rest (velocity 0,
//     or at the deepest depth when there is no velocity column) is dwell,
//     the others withdrawal. Without time_s, time is the sample number (no
//     dwell comparison then); without velocity_mm_per_s, the velocity is the
//     metadata speed (else 1 mm/s) with the phase's sign. A curve of the
//     older format (time, depth, velocity, force, states) thus reads as
//     before: its insertion is what it always was, parts are n/a.
// Every problem throws CurveFormatError naming file, line and column.
//
// Comparison (compare_curves, model against reference):
//   * only the INSERTION phase is compared: insertion samples with velocity
//     > 0 (any, without a velocity column); depths must not decrease in that
//     phase (a repeated depth is a force drop at one instant);
//   * the model force is interpolated piecewise linearly at the reference
//     depths; reference samples outside the model's depth range are skipped
//     (CurveComparison::n_compared counts the ones used);
//   * per layer (matched by name): the pressed interval is the depth range
//     where the reference's <layer>_state is "pressed"; a reference without
//     state columns has its punctures found from its force drops
//     (puncture_events.hpp) and layer k's pressed interval is from the end of
//     the cut through layer k - 1 (or the contact onset) to its puncture;
//     force RMSE inside it (N, and relative to the reference peak force); the
//     puncture event of a curve is the first insertion sample whose state is
//     "punctured": its depth, and as its force the maximum force over that
//     layer's pressed samples just before it, on the branch that rises to
//     the break: walking back from the break, the walk stops at a trough
//     (a fall from the largest force so far by more than 10 % of it, then a
//     rise by as much), so a layer met while the force still falls after the
//     break above (a layer pressed from the moment the one above gave way) is
//     not given the force of that earlier break.
#pragma once

#include <filesystem>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "puncture/io/provenance.hpp"
#include "puncture/model/realtime_model.hpp"
#include "puncture/puncture_force.hpp"
#include "puncture/scene.hpp"

namespace puncture::validation {

class CurveFormatError : public std::runtime_error {
 public:
  CurveFormatError(const std::string& file, int line, const std::string& column, const std::string& what);
  const std::string& file() const { return file_; }
  int line() const { return line_; }            ///< 1-based, 0 when not tied to a line
  const std::string& column() const { return column_; }  ///< column name, empty when not tied to one

 private:
  std::string file_;
  int line_;
  std::string column_;
};

/// Part of the trajectory a sample belongs to.
enum class CurvePhase { Insertion, Dwell, Withdrawal };
const char* to_string(CurvePhase phase);

struct InsertionCurve {
  std::string source;                              ///< file name or a description
  std::string content_hash;                        ///< FNV-1a 64 of the file bytes (hex), empty if not from a file
  std::map<std::string, std::string> metadata;     ///< "# key: value" lines
  std::vector<double> time_s;
  std::vector<double> depth_m;
  std::vector<double> velocity_m_per_s;
  std::vector<double> force_N;
  std::vector<std::string> layer_names;            ///< from the <layer>_state columns, file order
  std::vector<std::vector<LayerState>> layer_states;  ///< [layer][sample]
  std::vector<CurvePhase> phase;                   ///< per sample (column or inferred, see the header)
  /// The force's parts per sample (tip + cutting + friction = force); empty when the curve has none.
  std::vector<double> tip_force_N, cutting_force_N, friction_force_N;
  bool has_time = true;       ///< false: time_s is the sample number
  bool has_velocity = true;   ///< false: velocity_m_per_s is inferred from the phase
  bool phase_from_column = false;
  /// Depth (m) where the tip met the tissue when the reader knows it (a raw
  /// recording's contact fit, recording.hpp: 0); NaN otherwise (the contact
  /// onset is then found from the states or the force, puncture_events.hpp).
  double known_contact_depth_m = std::numeric_limits<double>::quiet_NaN();

  std::size_t size() const { return time_s.size(); }
  bool has_layer_states() const { return !layer_names.empty(); }
  bool has_parts() const { return !tip_force_N.empty(); }
  /// Index into layer_names, or -1.
  int layer_index(const std::string& name) const;
  /// Metadata value as a number (throws CurveFormatError if present but not a number).
  bool metadata_number(const std::string& key, double& value) const;
};

// read_insertion_curve / parse_insertion_curve (the schema above) and the
// raw rig recordings: recording.hpp.
/// The curve of a real-time run (total force, per-layer states).
/// include_damping = false: the force is the total minus every layer's damping
/// force d h v (what a quasi-static, frictionless reference can be compared
/// with); the curve's metadata then says "force: without damping".
InsertionCurve curve_from_run(const Scene& scene, const ScriptedRunResult& run, const std::string& source = "realtime",
                              bool include_damping = true);
/// The same curve as curve_from_run(scene, run_scripted_insertion(model, scene), ...),
/// recorded tick by tick: no tick results kept, no tick timed (what calibration runs need).
InsertionCurve simulate_curve(RealtimeModel& model, const Scene& scene, const std::string& source = "realtime",
                              bool include_damping = true);
/// CSV text in the reader's schema (depth and velocity in mm, states): the
/// provenance lines (when given), the curve's metadata, then the table.
std::string insertion_curve_csv(const InsertionCurve& curve, const io::Provenance* provenance = nullptr);

/// Indices of the insertion-phase samples (phase insertion and velocity > 0;
/// any velocity without a velocity column). Throws CurveFormatError (with the
/// sample's time) if depth decreases there, or if the phase is empty.
std::vector<std::size_t> insertion_phase(const InsertionCurve& curve);
/// Indices of the dwell samples (possibly none).
std::vector<std::size_t> dwell_phase(const InsertionCurve& curve);
/// Indices of the withdrawal samples (possibly none). Throws CurveFormatError
/// if depth increases there.
std::vector<std::size_t> withdrawal_phase(const InsertionCurve& curve);
/// Fills curve.phase from the velocity (or the depth) as described in the header.
void infer_phases(InsertionCurve& curve);

/// Piecewise-linear interpolation y(x) on strictly increasing x; false if
/// query lies outside [x.front(), x.back()].
bool interpolate_linear(const std::vector<double>& x, const std::vector<double>& y, double query, double& value);

struct PunctureEventMetrics {
  bool found = false;
  double depth_m = 0.0;
  double force_N = 0.0;
};

struct LayerMetrics {
  std::string layer;
  bool has_pressed_interval = false;
  double pressed_from_depth_m = 0.0;
  double pressed_to_depth_m = 0.0;
  std::size_t n_samples = 0;               ///< compared samples inside the pressed interval
  double force_rmse_N = 0.0;
  double force_rmse_relative = 0.0;        ///< force_rmse_N / reference peak force
  PunctureEventMetrics reference_puncture;
  PunctureEventMetrics model_puncture;
  double puncture_depth_error_m = 0.0;     ///< model - reference (0 unless both punctured)
  double puncture_force_error_N = 0.0;     ///< model - reference (0 unless both punctured)
};

struct CurveComparison {
  std::size_t n_compared = 0;
  double reference_peak_force_N = 0.0;     ///< max |force| over the reference insertion phase
  double force_rmse_N = 0.0;               ///< over all compared samples
  double force_rmse_relative = 0.0;
  double compared_from_depth_m = 0.0;
  double compared_to_depth_m = 0.0;
  std::vector<LayerMetrics> layers;        ///< one per layer name found in either curve (reference order first)
  const LayerMetrics* layer(const std::string& name) const;
};

struct LayerGeometry;
/// max_depth_m: compare only reference samples not deeper than this.
/// geometry: the scene's layers (puncture_events.hpp), used for a reference
/// without state columns to place the cut through each layer; without it
/// layer k's pressed interval runs from the previous puncture.
CurveComparison compare_curves(const InsertionCurve& model, const InsertionCurve& reference,
                               double max_depth_m = std::numeric_limits<double>::infinity(),
                               const std::vector<LayerGeometry>* geometry = nullptr);

/// Trough tolerance of puncture_event (fraction of the largest force so far).
constexpr double kPunctureTroughFraction = 0.1;

/// Puncture event of one layer on a curve (see the header comment).
PunctureEventMetrics puncture_event(const InsertionCurve& curve, const std::string& layer);

// ---------------------------------------------------------------------------
// Deflection profile of a layer surface at one needle depth.
// Model side: the force mesh's ring deflections dZ_j (m, positive INTO the
// tissue, j = 1..w) at ring radii r_j = (j - 1) L. Reference side: u_z(r) of
// the surface (m, z up, so the deflection into the tissue is -u_z) at radii r
// (strictly increasing). Rings outside the reference radii are skipped.
struct RadialProfile {
  int step = 0;
  double depth_m = 0.0;
  std::vector<double> r_m;
  std::vector<double> uz_m;
};
struct DeflectionProfileError {
  std::size_t n_rings = 0;              ///< rings compared
  double rmse_m = 0.0;
  double max_abs_error_m = 0.0;
  double relative_rmse = 0.0;           ///< rmse / max reference deflection over the compared rings
};
DeflectionProfileError deflection_profile_error(const std::vector<double>& ring_deflection_m, double spacing_L_m,
                                                const RadialProfile& reference);

/// fem_surface_profile.csv (columns step, depth_mm, r_mm, uz_mm): one profile per step.
std::vector<RadialProfile> read_surface_profiles(const std::filesystem::path& path);
std::vector<RadialProfile> parse_surface_profiles(const std::string& text, const std::string& source_name);
/// The profile whose depth is nearest to depth_m (throws std::invalid_argument if none).
const RadialProfile& profile_nearest_depth(const std::vector<RadialProfile>& profiles, double depth_m);

}  // namespace puncture::validation
