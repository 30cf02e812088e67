#include "puncture/validation/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "puncture/io/content_hash.hpp"
#include "puncture/io/atomic_file.hpp"
#include "puncture/io/csv_reader.hpp"
#include "puncture/io/csv_writer.hpp"
#include "puncture/validation/puncture_events.hpp"
#include "puncture/validation/recording.hpp"

namespace puncture::validation {

namespace {

constexpr double kMm = 1e-3;

std::string describe_time(const InsertionCurve& c, std::size_t i) {
  std::ostringstream s;
  s << "sample " << i + 1 << " (time_s = " << c.time_s[i] << ")";
  return s.str();
}

}  // namespace

CurveFormatError::CurveFormatError(const std::string& file, int line, const std::string& column, const std::string& what)
    : std::runtime_error(file + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " +
                         (column.empty() ? std::string() : "column '" + column + "': ") + what),
      file_(file),
      line_(line),
      column_(column) {}

const char* to_string(CurvePhase phase) {
  switch (phase) {
    case CurvePhase::Insertion: return "insertion";
    case CurvePhase::Dwell: return "dwell";
    case CurvePhase::Withdrawal: return "withdrawal";
  }
  return "unknown";
}

int InsertionCurve::layer_index(const std::string& name) const {
  for (std::size_t k = 0; k < layer_names.size(); ++k)
    if (layer_names[k] == name) return static_cast<int>(k);
  return -1;
}

bool InsertionCurve::metadata_number(const std::string& key, double& value) const {
  const auto it = metadata.find(key);
  if (it == metadata.end()) return false;
  if (!io::parse_finite_number(it->second, value))
    throw CurveFormatError(source, 0, "", "metadata '" + key + "' is not a finite number: '" + it->second + "'");
  return true;
}

void infer_phases(InsertionCurve& curve) {
  curve.phase.assign(curve.size(), CurvePhase::Insertion);
  if (curve.size() == 0) return;
  const std::size_t deepest = static_cast<std::size_t>(
      std::max_element(curve.depth_m.begin(), curve.depth_m.end()) - curve.depth_m.begin());
  const double max_depth = curve.depth_m[deepest];
  for (std::size_t i = deepest + 1; i < curve.size(); ++i) {
    const bool at_rest = curve.has_velocity ? curve.velocity_m_per_s[i] == 0.0 : curve.depth_m[i] == max_depth;
    curve.phase[i] = at_rest ? CurvePhase::Dwell : CurvePhase::Withdrawal;
  }
}


namespace {

InsertionCurve empty_run_curve(const Scene& scene, const std::string& source, bool include_damping, std::size_t n) {
  InsertionCurve c;
  c.source = source;
  if (!include_damping) c.metadata["force"] = "without damping (total minus d h v of every layer)";
  for (const Layer& l : scene.layers) c.layer_names.push_back(l.name);
  c.layer_states.resize(scene.layers.size());
  c.time_s.reserve(n), c.depth_m.reserve(n), c.velocity_m_per_s.reserve(n), c.force_N.reserve(n);
  c.tip_force_N.reserve(n), c.cutting_force_N.reserve(n), c.friction_force_N.reserve(n), c.phase.reserve(n);
  for (auto& s : c.layer_states) s.reserve(n);
  c.phase_from_column = true;
  return c;
}

/// Appends one tick; its phase from the scripted trajectory of the run.
void append_tick(InsertionCurve& c, const TickResult& t, const ScriptedTrajectory& trajectory, bool include_damping) {
  double force = t.total_force_N, damping = 0.0;
  if (!include_damping)
    for (const auto& layer : t.layers) force -= layer.damping_force_N, damping += layer.damping_force_N;
  c.time_s.push_back(t.time_s);
  c.depth_m.push_back(t.depth_m);
  c.velocity_m_per_s.push_back(t.velocity_m_per_s);
  c.force_N.push_back(force);
  for (std::size_t k = 0; k < c.layer_states.size() && k < t.layers.size(); ++k) c.layer_states[k].push_back(t.layers[k].state);
  c.tip_force_N.push_back(t.tip_force_N);
  c.cutting_force_N.push_back(t.cutting_force_N);
  c.friction_force_N.push_back(t.friction_force_N - damping);
  c.phase.push_back(t.time_s < trajectory.insertion_end_s()      ? CurvePhase::Insertion
                    : t.time_s < trajectory.withdrawal_start_s() ? CurvePhase::Dwell
                                                                 : CurvePhase::Withdrawal);
}

}  // namespace

InsertionCurve curve_from_run(const Scene& scene, const ScriptedRunResult& run, const std::string& source,
                              bool include_damping) {
  InsertionCurve c = empty_run_curve(scene, source, include_damping, run.ticks.size());
  const ScriptedTrajectory trajectory(scene.insertion);
  for (const TickResult& t : run.ticks) append_tick(c, t, trajectory, include_damping);
  return c;
}

InsertionCurve simulate_curve(RealtimeModel& model, const Scene& scene, const std::string& source,
                              bool include_damping) {
  if (!model.simulator) throw std::invalid_argument("simulate_curve: model has no simulator");
  ScriptedNeedleDevice device(scene.insertion);
  const long n_ticks = scripted_tick_count(scene);
  const double dt = 1.0 / scene.realtime.haptic_rate_Hz;
  InsertionCurve c = empty_run_curve(scene, source, include_damping, static_cast<std::size_t>(n_ticks));
  for (long i = 0; i < n_ticks; ++i)
    append_tick(c, model.simulator->tick(device.read(static_cast<double>(i) * dt)), device.trajectory(), include_damping);
  return c;
}

std::string insertion_curve_csv(const InsertionCurve& curve, const io::Provenance* provenance) {
  std::vector<std::string> columns{"time_s", "depth_mm", "velocity_mm_per_s", "force_N"};
  if (curve.has_parts()) columns.insert(columns.end(), {"tip_force_N", "cutting_force_N", "friction_force_N"});
  const bool phases = curve.phase.size() == curve.size();
  if (phases) columns.push_back("phase");
  for (const auto& name : curve.layer_names) columns.push_back(name + "_state");
  io::CsvWriter csv(columns);
  if (provenance) csv.add_provenance(*provenance);
  for (const auto& [k, v] : curve.metadata)
    if (!provenance || (k != "command" && k != "program_version" && k != "git_revision" && k != "date_utc" &&
                        k != "machine"))
      csv.add_metadata(k, v);
  for (std::size_t i = 0; i < curve.size(); ++i) {
    csv.number(curve.time_s[i]).number(curve.depth_m[i] / kMm).number(curve.velocity_m_per_s[i] / kMm).number(curve.force_N[i]);
    if (curve.has_parts()) csv.number(curve.tip_force_N[i]).number(curve.cutting_force_N[i]).number(curve.friction_force_N[i]);
    if (phases) csv.text(to_string(curve.phase[i]));
    for (const auto& states : curve.layer_states) csv.text(to_string(states[i]));
    csv.end_row();
  }
  return csv.str();
}

namespace {
/// The curve's phases: its own, or inferred when a caller built it by hand.
std::vector<CurvePhase> phases_of(const InsertionCurve& curve) {
  if (curve.phase.size() == curve.size()) return curve.phase;
  InsertionCurve copy;
  copy.depth_m = curve.depth_m;
  copy.velocity_m_per_s = curve.velocity_m_per_s;
  copy.time_s = curve.time_s;
  copy.has_velocity = curve.has_velocity;
  infer_phases(copy);
  return copy.phase;
}
}  // namespace

std::vector<std::size_t> dwell_phase(const InsertionCurve& curve) {
  const std::vector<CurvePhase> phase = phases_of(curve);
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < curve.size(); ++i)
    if (phase[i] == CurvePhase::Dwell) idx.push_back(i);
  return idx;
}

std::vector<std::size_t> withdrawal_phase(const InsertionCurve& curve) {
  const std::vector<CurvePhase> phase = phases_of(curve);
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < curve.size(); ++i) {
    if (phase[i] != CurvePhase::Withdrawal) continue;
    if (!idx.empty() && curve.depth_m[i] > curve.depth_m[idx.back()])
      throw CurveFormatError(curve.source, 0, "depth_mm", "depth increases during the withdrawal at " + describe_time(curve, i));
    idx.push_back(i);
  }
  return idx;
}

std::vector<std::size_t> insertion_phase(const InsertionCurve& curve) {
  if (curve.size() == 0) throw CurveFormatError(curve.source, 0, "", "empty curve");
  const std::vector<CurvePhase> phase = phases_of(curve);
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < curve.size(); ++i) {
    if (phase[i] != CurvePhase::Insertion) continue;
    if (curve.has_velocity && !(curve.velocity_m_per_s[i] > 0.0)) continue;
    // Non-decreasing: a repeated depth is a force drop at one instant
    // (interpolation then takes the value after the drop).
    if (!idx.empty() && !(curve.depth_m[i] >= curve.depth_m[idx.back()]))
      throw CurveFormatError(curve.source, 0, "depth_mm",
                             "depth decreases during the insertion phase (velocity > 0) at " + describe_time(curve, i));
    idx.push_back(i);
  }
  if (idx.empty()) throw CurveFormatError(curve.source, 0, "velocity_mm_per_s", "no insertion phase (no sample with velocity > 0)");
  return idx;
}

bool interpolate_linear(const std::vector<double>& x, const std::vector<double>& y, double query, double& value) {
  if (x.empty() || x.size() != y.size() || !(query >= x.front()) || !(query <= x.back())) return false;
  const auto it = std::upper_bound(x.begin(), x.end(), query);
  if (it == x.end()) {
    value = y.back();
    return true;
  }
  const std::size_t hi = static_cast<std::size_t>(it - x.begin());
  if (hi == 0) {
    value = y.front();
    return true;
  }
  const std::size_t lo = hi - 1;
  const double t = (query - x[lo]) / (x[hi] - x[lo]);
  value = y[lo] + t * (y[hi] - y[lo]);
  return true;
}

PunctureEventMetrics puncture_event(const InsertionCurve& curve, const std::string& layer) {
  PunctureEventMetrics e;
  const int k = curve.layer_index(layer);
  if (k < 0) return e;
  const auto& states = curve.layer_states[static_cast<std::size_t>(k)];
  const std::vector<std::size_t> phase = insertion_phase(curve);
  for (std::size_t p = 0; p < phase.size(); ++p) {
    if (states[phase[p]] != LayerState::Punctured) continue;
    e.found = true;
    e.depth_m = curve.depth_m[phase[p]];
    // Maximum force over the contiguous pressed samples just before the event,
    // back to the trough before the rise to the break (the header comment);
    // the previous sample's force if the layer broke without a pressed sample.
    double peak = -std::numeric_limits<double>::infinity();
    double low_since_peak = std::numeric_limits<double>::infinity();
    std::size_t q = p;
    while (q > 0 && states[phase[q - 1]] == LayerState::Pressed) {
      const double f = curve.force_N[phase[q - 1]];
      const double tol = kPunctureTroughFraction * std::abs(peak);
      if (std::isfinite(peak) && low_since_peak < peak - tol && f > low_since_peak + tol) break;
      --q;
      if (f > peak) peak = low_since_peak = f;
      else low_since_peak = std::min(low_since_peak, f);
    }
    if (!std::isfinite(peak)) peak = curve.force_N[phase[p > 0 ? p - 1 : p]];
    e.force_N = peak;
    return e;
  }
  return e;
}

DeflectionProfileError deflection_profile_error(const std::vector<double>& ring_deflection_m, double spacing_L_m,
                                                const RadialProfile& reference) {
  if (!(spacing_L_m > 0.0) || !std::isfinite(spacing_L_m))
    throw std::invalid_argument("deflection_profile_error: spacing L must be finite and > 0");
  if (reference.r_m.size() != reference.uz_m.size() || reference.r_m.size() < 2)
    throw std::invalid_argument("deflection_profile_error: the reference profile needs >= 2 (r, u_z) points of equal count");
  for (std::size_t i = 1; i < reference.r_m.size(); ++i)
    if (!(reference.r_m[i] > reference.r_m[i - 1]))
      throw std::invalid_argument("deflection_profile_error: reference radii must increase strictly");
  DeflectionProfileError e;
  double sq = 0.0, ref_max = 0.0;
  for (std::size_t j = 0; j < ring_deflection_m.size(); ++j) {
    if (!std::isfinite(ring_deflection_m[j]))
      throw std::invalid_argument("deflection_profile_error: non-finite ring deflection at ring " + std::to_string(j + 1));
    const double r = static_cast<double>(j) * spacing_L_m;
    double uz = 0.0;
    if (!interpolate_linear(reference.r_m, reference.uz_m, r, uz)) continue;
    const double ref_deflection = -uz;
    const double diff = ring_deflection_m[j] - ref_deflection;
    sq += diff * diff;
    e.max_abs_error_m = std::max(e.max_abs_error_m, std::abs(diff));
    ref_max = std::max(ref_max, std::abs(ref_deflection));
    ++e.n_rings;
  }
  if (e.n_rings > 0) e.rmse_m = std::sqrt(sq / static_cast<double>(e.n_rings));
  e.relative_rmse = ref_max > 0.0 ? e.rmse_m / ref_max : 0.0;
  return e;
}

std::vector<RadialProfile> parse_surface_profiles(const std::string& text, const std::string& source_name) {
  const io::CsvDocument doc = parse_curve_csv(text, source_name);
  const std::size_t c_step = doc.require_column("step"), c_depth = doc.require_column("depth_mm"),
                    c_r = doc.require_column("r_mm"), c_uz = doc.require_column("uz_mm");
  std::vector<RadialProfile> out;
  for (const io::CsvRecord& record : doc.records) {
    const int line_no = record.line;
    auto number = [&](std::size_t col) {
      double v = 0.0;
      if (!io::parse_finite_number(record.fields[col], v))
        throw CurveFormatError(source_name, line_no, doc.header[col], "not a finite number: '" + record.fields[col] + "'");
      return v;
    };
    const double step = number(c_step);
    if (step != std::floor(step)) throw CurveFormatError(source_name, line_no, "step", "must be an integer");
    const int s = static_cast<int>(step);
    const double depth = number(c_depth) * kMm, r = number(c_r) * kMm, uz = number(c_uz) * kMm;
    if (out.empty() || out.back().step != s) {
      for (const auto& p : out)
        if (p.step == s) throw CurveFormatError(source_name, line_no, "step", "rows of step " + std::to_string(s) + " are not contiguous");
      out.push_back(RadialProfile{s, depth, {}, {}});
    } else {
      if (depth != out.back().depth_m) throw CurveFormatError(source_name, line_no, "depth_mm", "depth changes within one step");
      if (!(r > out.back().r_m.back())) throw CurveFormatError(source_name, line_no, "r_mm", "radius must increase strictly within a step");
    }
    out.back().r_m.push_back(r);
    out.back().uz_m.push_back(uz);
  }
  if (out.empty()) throw CurveFormatError(source_name, 0, "", "no profile rows");
  return out;
}

std::vector<RadialProfile> read_surface_profiles(const std::filesystem::path& path) {
  return parse_surface_profiles(read_curve_file_bytes(path), path.string());
}

const RadialProfile& profile_nearest_depth(const std::vector<RadialProfile>& profiles, double depth_m) {
  if (profiles.empty()) throw std::invalid_argument("profile_nearest_depth: no profiles");
  const RadialProfile* best = &profiles.front();
  for (const auto& p : profiles)
    if (std::abs(p.depth_m - depth_m) < std::abs(best->depth_m - depth_m)) best = &p;
  return *best;
}

}  // namespace puncture::validation
