// A raw rig recording (time, stage position, force) converted into an
// insertion curve: phases from the stage, the noise, contact and tare from
// the force (recording.hpp has the rules). Times in s, positions in m, forces
// in N inside.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "puncture/io/atomic_file.hpp"
#include "puncture/io/content_hash.hpp"
#include "puncture/validation/force_noise.hpp"
#include "puncture/validation/number_format.hpp"
#include "puncture/validation/puncture_events.hpp"
#include "puncture/validation/recording.hpp"

namespace puncture::validation {

namespace {

/// The three columns in SI units: stage travel positive into the tissue.
struct RawSamples {
  std::vector<double> t_s, stage_m, force_N;
  std::vector<int> line;  ///< CSV line of each sample
  double position_unit_m = 1.0;
  int direction = 1;
};

std::size_t column_of(const io::CsvDocument& doc, const RecordingFormat& f, const RecordingColumn& c, const char* key) {
  const int j = doc.column(c.name);
  if (j >= 0) return static_cast<std::size_t>(j);
  std::string header;
  for (const std::string& h : doc.header) header += (header.empty() ? "" : ", ") + h;
  throw RecordingError(doc.source, "", "column '" + c.name + "' (" + key + ".column of " + f.source +
                                           ") is not in the header (" + header + ")");
}

RawSamples raw_samples(const io::CsvDocument& doc, const RecordingFormat& f) {
  const std::size_t jt = column_of(doc, f, f.time, "time"), jx = column_of(doc, f, f.position, "position"),
                    jf = column_of(doc, f, f.force, "force");
  const double ut = unit_factor(f, f.time, "time.unit", "time"), ux = unit_factor(f, f.position, "position.unit", "position"),
               uf = unit_factor(f, f.force, "force.unit", "force");
  RawSamples r;
  r.position_unit_m = ux;
  r.direction = f.into_tissue == StageDirection::Decreasing ? -1 : 1;
  for (const io::CsvRecord& rec : doc.records) {
    auto number = [&](std::size_t j) {
      double v = 0.0;
      if (!io::parse_finite_number(rec.fields[j], v))
        throw CurveFormatError(doc.source, rec.line, doc.header[j], "not a finite number: '" + rec.fields[j] + "'");
      return v;
    };
    r.t_s.push_back(number(jt) * ut);
    r.stage_m.push_back(r.direction * number(jx) * ux);
    r.force_N.push_back(f.force_sign * number(jf) * uf);
    r.line.push_back(rec.line);
    if (r.t_s.size() >= 2 && !(r.t_s.back() > r.t_s[r.t_s.size() - 2]))
      throw CurveFormatError(doc.source, rec.line, doc.header[jt], "time must increase");
  }
  if (r.t_s.size() < 2) throw RecordingError(doc.source, "", "fewer than two data rows");
  return r;
}

/// Where the insertion ends and the hold and the withdrawal start.
struct StagePhases {
  std::size_t deepest = 0;           ///< first sample at the deepest position (last of the insertion)
  std::size_t hold_from = 0, withdrawal_from = 0;
};

/// Phases from the stage travel (clamping jitter below kStageRestTolerance_m);
/// throws RecordingError for a stage that does not move or moves back and forth.
StagePhases stage_phases(RawSamples& r, const std::string& source, const std::string& column) {
  const auto [lo_at, hi_at] = std::minmax_element(r.stage_m.begin(), r.stage_m.end());
  const double lo = *lo_at, top = *hi_at, travel = top - lo;
  if (!(travel >= kMinStageTravel_m))
    throw RecordingError(source, "", "the stage does not move: column '" + column + "' spans " +
                                         significant_digits(travel * 1e3, 3) + " mm (at least " +
                                         significant_digits(kMinStageTravel_m * 1e3, 3) + " mm of travel needed)");
  StagePhases p;
  const double tol = kStageRestTolerance_m;
  while (r.stage_m[p.deepest] < top - tol) ++p.deepest;
  for (std::size_t i = 1; i <= p.deepest; ++i) {
    if (r.stage_m[i] < r.stage_m[i - 1] - tol)
      throw RecordingError(source, "", "line " + std::to_string(r.line[i]) + ": the stage moves back by " +
                                           significant_digits((r.stage_m[i - 1] - r.stage_m[i]) * 1e3, 3) +
                                           " mm before it reaches its deepest position (one insertion per file)");
    r.stage_m[i] = std::max(r.stage_m[i], r.stage_m[i - 1]);
  }
  p.hold_from = p.deepest + 1;
  p.withdrawal_from = p.hold_from;
  while (p.withdrawal_from < r.stage_m.size() && r.stage_m[p.withdrawal_from] >= top - tol) ++p.withdrawal_from;
  for (std::size_t i = p.withdrawal_from + 1; i < r.stage_m.size(); ++i) {
    if (r.stage_m[i] > r.stage_m[i - 1] + tol)
      throw RecordingError(source, "", "line " + std::to_string(r.line[i]) +
                                           ": the stage moves in again during the withdrawal (one insertion per file)");
    r.stage_m[i] = std::min(r.stage_m[i], r.stage_m[i - 1]);
  }
  return p;
}

/// Median stage speed (m/s, > 0) over samples [from, to) moving in `sign`; 0 if none.
double median_speed(const RawSamples& r, std::size_t from, std::size_t to, int sign) {
  std::vector<double> v;
  for (std::size_t i = std::max<std::size_t>(from, 1); i < to && i < r.t_s.size(); ++i) {
    const double dv = sign * (r.stage_m[i] - r.stage_m[i - 1]);
    if (dv > kStageRestTolerance_m) v.push_back(dv / (r.t_s[i] - r.t_s[i - 1]));
  }
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

/// Least squares of F ~ c0 + c u^p (u = max(0, s - z0), in mm; c >= 0, else
/// the constant alone) over every `thin`-th sample of [0, n); returns the
/// residual sum of squares and c0. (A free linear term besides u^p would let
/// any later z0 fit as well: a (u + d)^2 = a d^2 + 2 a d u + a u^2.)
double hinge_fit(const std::vector<double>& s, const std::vector<double>& F, std::size_t n, std::size_t thin,
                 double z0, double p, double& c0) {
  double n1 = 0.0, sg = 0.0, sgg = 0.0, sf = 0.0, sgf = 0.0, sff = 0.0;
  for (std::size_t i = 0; i < n; i += thin) {
    const double u = std::max(0.0, s[i] - z0) * 1e3, g = u > 0.0 ? std::pow(u, p) : 0.0;
    n1 += 1.0, sg += g, sgg += g * g, sf += F[i], sgf += g * F[i], sff += F[i] * F[i];
  }
  const double det = n1 * sgg - sg * sg;
  const double c = det > 0.0 ? (n1 * sgf - sg * sf) / det : 0.0;
  if (!(c > 0.0)) {  // the constant alone
    c0 = sf / n1;
    return sff - sf * c0;
  }
  c0 = (sf - c * sg) / n1;
  return sff - c0 * sf - c * sgf;
}

struct ContactFit {
  double contact_m = 0.0, tare_N = 0.0;
};

/// Contact and tare (see the header) over the insertion samples [0, n), the
/// fit ending at the latest at sample `first_drop` (the first drop's maximum).
ContactFit fit_contact(const RawSamples& r, std::size_t n, std::size_t first_drop, double sigma, const std::string& source) {
  std::vector<double> start(r.force_N.begin(), r.force_N.begin() + static_cast<long>(std::min(n, kMinNoiseSamples)));
  std::nth_element(start.begin(), start.begin() + static_cast<long>(start.size() / 2), start.end());
  const double level = start[start.size() / 2];
  double rise = 0.0, fall = 0.0;
  for (std::size_t i = 0; i < n; ++i) rise = std::max(rise, r.force_N[i] - level), fall = std::max(fall, level - r.force_N[i]);
  const double needed = PunctureDetectionOptions{}.min_peak_sigmas * sigma;
  if (!(rise > needed))
    throw RecordingError(source, "", "the force never leaves the noise during the insertion (largest rise " +
                                         significant_digits(rise, 3) + " N above its starting level, noise " +
                                         significant_digits(sigma, 3) + " N; largest fall " + significant_digits(fall, 3) +
                                         " N: is force.sign right?)");
  double first_rise = 0.0;  // the largest rise before the first drop
  for (std::size_t i = 0; i < n && i <= first_drop; ++i) first_rise = std::max(first_rise, r.force_N[i] - level);
  const double fit_rise = std::max(kContactFitRise * first_rise, 20.0 * sigma);
  std::size_t end = 0;
  while (end < n && r.force_N[end] - level < fit_rise) ++end;
  double best = std::numeric_limits<double>::infinity();
  ContactFit fit;
  double exponent = 2.0;
  const std::size_t thin = std::max<std::size_t>(1, end / 4000);
  auto consider = [&](double z0, double p) {
    double c0 = 0.0;
    const double sse = hinge_fit(r.stage_m, r.force_N, end, thin, z0, p, c0);
    if (sse < best) best = sse, fit.contact_m = z0, fit.tare_N = c0, exponent = p;
  };
  if (end < kMinNoiseSamples)
    throw RecordingError(source, "", "the recording starts in contact: the force has risen after " +
                                         std::to_string(end) + " sample(s) (at least " + std::to_string(kMinNoiseSamples) +
                                         " samples before contact needed to tare the sensor from)");
  // Candidates: up to where the force is surely off its starting level (10 sigma).
  std::size_t candidates = 0;
  while (candidates < end && r.force_N[candidates] - level <= std::max(10.0 * sigma, 1e-6 * first_rise)) ++candidates;
  const std::size_t stride = std::max<std::size_t>(1, candidates / 1000);
  for (double p = kContactExponents[0]; p <= kContactExponents[1] + 1e-9; p += kContactExponents[2])
    for (std::size_t j = 0; j <= candidates && j < end; j += stride) consider(r.stage_m[j], p);
  const double around = fit.contact_m, p_best = exponent;
  const double step = stride * (r.stage_m[end - 1] - r.stage_m[0]) / static_cast<double>(end - 1);
  for (int k = -20; k <= 20; ++k) consider(around + 0.05 * k * step, p_best);  // between the samples
  std::size_t before = 0;
  while (before < n && r.stage_m[before] < fit.contact_m) ++before;
  if (before < kMinNoiseSamples)
    throw RecordingError(source, "", "the recording starts in contact: " + std::to_string(before) +
                                         " sample(s) before the contact (at least " + std::to_string(kMinNoiseSamples) +
                                         " needed to tare the sensor from)");
  return fit;
}

/// The curve in stage coordinates with the phases and their velocities.
InsertionCurve staged_curve(const RawSamples& r, const StagePhases& p, double v_in, double v_out, const std::string& source) {
  InsertionCurve c;
  c.source = source;
  c.has_time = true;
  c.has_velocity = false;
  c.phase_from_column = true;
  for (std::size_t i = 0; i < r.t_s.size(); ++i) {
    const CurvePhase ph = i <= p.deepest ? CurvePhase::Insertion : i < p.withdrawal_from ? CurvePhase::Dwell : CurvePhase::Withdrawal;
    c.time_s.push_back(r.t_s[i] - r.t_s[0]);
    c.depth_m.push_back(r.stage_m[i]);
    c.force_N.push_back(r.force_N[i]);
    c.phase.push_back(ph);
    c.velocity_m_per_s.push_back(ph == CurvePhase::Insertion ? v_in : ph == CurvePhase::Withdrawal ? -v_out : 0.0);
  }
  return c;
}

/// The sample of the first force drop's maximum on the untared curve in stage
/// coordinates (the force less its starting level); the curve's size if none.
std::size_t first_drop_at(InsertionCurve c, double sigma) {
  std::vector<double> start(c.force_N.begin(), c.force_N.begin() + static_cast<long>(std::min(c.size(), kMinNoiseSamples)));
  std::nth_element(start.begin(), start.begin() + static_cast<long>(start.size() / 2), start.end());
  for (double& f : c.force_N) f -= start[start.size() / 2];
  const std::vector<ForceDrop> drops = detect_force_drops(c, sigma, PunctureDetectionOptions{});
  return drops.empty() ? c.size() : drops.front().index;
}

std::string number_text(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

}  // namespace

RawRecording curve_from_raw_recording(const io::CsvDocument& doc, const RecordingFormat& format) {
  check_recording_format(format);
  RawSamples r = raw_samples(doc, format);
  const StagePhases p = stage_phases(r, doc.source, format.position.name);
  RawRecording out;
  RecordingAnalysis& a = out.analysis;
  a.insertion_speed_m_per_s = median_speed(r, 0, p.deepest + 1, +1);
  a.withdrawal_speed_m_per_s = median_speed(r, p.withdrawal_from, r.t_s.size(), -1);
  InsertionCurve c = staged_curve(r, p, a.insertion_speed_m_per_s, a.withdrawal_speed_m_per_s, doc.source);
  std::vector<std::size_t> insertion(p.deepest + 1);
  for (std::size_t i = 0; i <= p.deepest; ++i) insertion[i] = i;
  a.noise_N = force_noise_sigma_N(c, insertion);
  const ContactFit fit = fit_contact(r, p.deepest + 1, first_drop_at(c, a.noise_N), a.noise_N, doc.source);
  a.tare_N = fit.tare_N;
  a.hold_from = p.hold_from;
  a.withdrawal_from = p.withdrawal_from;
  std::size_t k = 0;
  while (k + 1 < r.stage_m.size() && r.stage_m[k + 1] <= fit.contact_m) ++k;  // the last sample before contact
  const double span = r.stage_m[k + 1] - r.stage_m[k];
  const double w = span > 0.0 ? (fit.contact_m - r.stage_m[k]) / span : 0.0;
  a.contact_time_s = c.time_s[k] + w * (c.time_s[k + 1] - c.time_s[k]);
  a.contact_stage = r.direction * fit.contact_m / r.position_unit_m;
  for (double& d : c.depth_m) d -= fit.contact_m;
  c.known_contact_depth_m = 0.0;
  for (double& f : c.force_N) f -= fit.tare_N;
  c.metadata = doc.metadata_map();
  c.metadata["recording_format"] = format.source;
  c.metadata["speed_mm_per_s"] = number_text(a.insertion_speed_m_per_s * 1e3);
  if (a.withdrawal_speed_m_per_s > 0.0) c.metadata["withdrawal_speed_mm_per_s"] = number_text(a.withdrawal_speed_m_per_s * 1e3);
  c.metadata["tare_N"] = number_text(a.tare_N);
  c.metadata["noise_N"] = number_text(a.noise_N);
  c.metadata["contact_time_s"] = number_text(a.contact_time_s);
  c.metadata["contact_" + format.position.name] = number_text(a.contact_stage);
  out.curve = std::move(c);
  return out;
}

InsertionCurve read_reference_recording(const std::filesystem::path& csv, const ReferenceRecordingOptions& options) {
  RecordingFormat format;
  const std::filesystem::path sidecar = recording_sidecar_path(csv);
  if (!options.format_file.empty()) format = read_recording_format(options.format_file);
  else if (std::filesystem::exists(sidecar)) format = read_recording_format(sidecar);
  format = merge_recording_formats(format, options.overrides);
  if (format.empty()) {
    try {
      return read_insertion_curve(csv);
    } catch (const CurveFormatError& e) {
      if (e.column() != "depth_mm") throw;
      throw CurveFormatError(e.file(), e.line(), e.column(),
                             "required column missing from the header; a raw rig recording (time, stage position, "
                             "force) needs its format: a sidecar " + sidecar.filename().string() +
                                 " beside it, --recording-format FILE or the --time-column ... options "
                                 "(validation/README.md, raw recordings)");
    }
  }
  std::string bytes;
  try {
    bytes = io::read_text_file(csv);
  } catch (const std::runtime_error& e) {
    throw CurveFormatError(csv.string(), 0, "", e.what());
  }
  RawRecording raw = curve_from_raw_recording(io::parse_csv(bytes, csv.string()), format);
  raw.curve.content_hash = io::fnv1a64_hex(bytes);
  return raw.curve;
}

}  // namespace puncture::validation
