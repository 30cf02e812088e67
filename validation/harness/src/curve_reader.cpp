// The reader of insertion curves in the schema of metrics.hpp (recording.hpp):
// depth_mm and force_N required, time, velocity, phase, force parts and layer
// states optional; every problem throws CurveFormatError naming file, line and column.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "puncture/io/content_hash.hpp"
#include "puncture/io/atomic_file.hpp"
#include "puncture/io/csv_reader.hpp"
#include "puncture/validation/recording.hpp"

namespace puncture::validation {

namespace {

constexpr double kMm = 1e-3;

bool parse_state(const std::string& text, LayerState& state) {
  if (text == "untouched") state = LayerState::Untouched;
  else if (text == "pressed") state = LayerState::Pressed;
  else if (text == "punctured") state = LayerState::Punctured;
  else return false;
  return true;
}

bool parse_phase(const std::string& text, CurvePhase& phase) {
  // "approach": the FEM's needle moving down before it touches; it is part of
  // the insertion stroke.
  if (text == "insertion" || text == "approach") phase = CurvePhase::Insertion;
  else if (text == "dwell") phase = CurvePhase::Dwell;
  else if (text == "withdrawal") phase = CurvePhase::Withdrawal;
  else return false;
  return true;
}

/// Where each column of an insertion curve stands (-1: absent).
struct CurveColumns {
  int time = -1, depth = -1, velocity = -1, force = -1, phase = -1, tip = -1, cutting = -1, friction = -1;
  std::vector<int> states;  ///< the <layer>_state columns, file order
};

/// The columns of the header (layer names into curve.layer_names); throws when a
/// required one is missing or the force's parts are incomplete.
CurveColumns curve_columns(const io::CsvDocument& doc, const std::string& source_name, InsertionCurve& curve) {
  CurveColumns c;
  for (std::size_t j = 0; j < doc.header.size(); ++j) {
    const std::string& h = doc.header[j];
    const int jj = static_cast<int>(j);
    if (h == "time_s") c.time = jj;
    else if (h == "depth_mm") c.depth = jj;
    else if (h == "velocity_mm_per_s") c.velocity = jj;
    else if (h == "force_N") c.force = jj;
    else if (h == "phase") c.phase = jj;
    else if (h == "tip_force_N") c.tip = jj;
    else if (h == "cutting_force_N") c.cutting = jj;
    else if (h == "friction_force_N") c.friction = jj;
    else if (h.size() > 6 && h.compare(h.size() - 6, 6, "_state") == 0) {
      c.states.push_back(jj);
      curve.layer_names.push_back(h.substr(0, h.size() - 6));
    }
  }
  const std::pair<int, const char*> required[] = {{c.depth, "depth_mm"}, {c.force, "force_N"}};
  for (const auto& [col, name] : required)
    if (col < 0) throw CurveFormatError(source_name, doc.header_line, name, "required column missing from the header");
  const int parts = (c.tip >= 0) + (c.cutting >= 0) + (c.friction >= 0);
  if (parts != 0 && parts != 3)
    throw CurveFormatError(source_name, doc.header_line,
                           c.tip < 0 ? "tip_force_N" : c.cutting < 0 ? "cutting_force_N" : "friction_force_N",
                           "the force's parts go together: tip_force_N, cutting_force_N and friction_force_N");
  return c;
}

/// Appends one data row to the curve (errors name the file, line and column).
void append_record(const io::CsvDocument& doc, const io::CsvRecord& record, const CurveColumns& c,
                   const std::string& source_name, InsertionCurve& curve) {
  const int line_no = record.line;
  const std::vector<std::string>& fields = record.fields;
  auto number = [&](int col, double scale) {
    double v = 0.0;
    if (!io::parse_finite_number(fields[static_cast<std::size_t>(col)], v))
      throw CurveFormatError(source_name, line_no, doc.header[static_cast<std::size_t>(col)],
                             "not a finite number: '" + fields[static_cast<std::size_t>(col)] + "'");
    return v * scale;
  };
  curve.time_s.push_back(c.time >= 0 ? number(c.time, 1.0) : static_cast<double>(curve.time_s.size()));
  curve.depth_m.push_back(number(c.depth, kMm));
  curve.velocity_m_per_s.push_back(c.velocity >= 0 ? number(c.velocity, kMm) : 0.0);
  curve.force_N.push_back(number(c.force, 1.0));
  if (c.tip >= 0) {
    curve.tip_force_N.push_back(number(c.tip, 1.0));
    curve.cutting_force_N.push_back(number(c.cutting, 1.0));
    curve.friction_force_N.push_back(number(c.friction, 1.0));
  }
  if (c.phase >= 0) {
    CurvePhase ph;
    const std::string& f = fields[static_cast<std::size_t>(c.phase)];
    if (!parse_phase(f, ph))
      throw CurveFormatError(source_name, line_no, "phase", "phase must be approach, insertion, dwell or withdrawal (got '" + f + "')");
    curve.phase.push_back(ph);
  }
  for (std::size_t k = 0; k < c.states.size(); ++k) {
    LayerState s;
    const std::string& f = fields[static_cast<std::size_t>(c.states[k])];
    if (!parse_state(f, s))
      throw CurveFormatError(source_name, line_no, doc.header[static_cast<std::size_t>(c.states[k])],
                             "layer state must be untouched, pressed or punctured (got '" + f + "')");
    curve.layer_states[k].push_back(s);
  }
  // Time increases; a repeated time is allowed only at the same depth: a
  // force drop at one instant (a quasi-static reference records the state
  // before and after a breakthrough at the same load step).
  if (curve.size() >= 2) {
    const std::size_t n = curve.size();
    const bool later = curve.time_s[n - 1] > curve.time_s[n - 2];
    const bool same_instant = curve.time_s[n - 1] == curve.time_s[n - 2] && curve.depth_m[n - 1] == curve.depth_m[n - 2];
    if (!later && !same_instant)
      throw CurveFormatError(source_name, line_no, "time_s",
                             "time must increase (a repeated time is allowed only at the same depth)");
  }
}

/// A curve without a velocity column: the sign from the phase, the magnitude
/// from the metadata speed (else 1 mm/s).
void velocity_from_phases(InsertionCurve& curve) {
  double speed = 1.0;
  curve.metadata_number("speed_mm_per_s", speed);
  for (std::size_t i = 0; i < curve.size(); ++i)
    curve.velocity_m_per_s[i] = curve.phase[i] == CurvePhase::Insertion    ? speed * kMm
                                : curve.phase[i] == CurvePhase::Withdrawal ? -speed * kMm
                                                                           : 0.0;
}

}  // namespace

InsertionCurve parse_insertion_curve(const std::string& text, const std::string& source_name) {
  InsertionCurve curve;
  curve.source = source_name;
  const io::CsvDocument doc = parse_curve_csv(text, source_name);
  curve.metadata = doc.metadata_map();
  const CurveColumns columns = curve_columns(doc, source_name, curve);
  curve.has_time = columns.time >= 0;
  curve.has_velocity = columns.velocity >= 0;
  curve.phase_from_column = columns.phase >= 0;
  curve.layer_states.resize(columns.states.size());
  for (const io::CsvRecord& record : doc.records) append_record(doc, record, columns, source_name, curve);
  if (curve.size() == 0) throw CurveFormatError(source_name, 0, "", "no data rows");
  if (!curve.phase_from_column) infer_phases(curve);
  if (!curve.has_velocity) velocity_from_phases(curve);
  return curve;
}

InsertionCurve read_insertion_curve(const std::filesystem::path& path) {
  const std::string bytes = read_curve_file_bytes(path);
  InsertionCurve c = parse_insertion_curve(bytes, path.string());
  c.content_hash = io::fnv1a64_hex(bytes);
  return c;
}

std::string read_curve_file_bytes(const std::filesystem::path& path) {
  try {
    return io::read_text_file(path);
  } catch (const std::runtime_error& e) {
    throw CurveFormatError(path.string(), 0, "", e.what());
  }
}

io::CsvDocument parse_curve_csv(const std::string& text, const std::string& source_name) {
  try {
    return io::parse_csv(text, source_name);
  } catch (const io::CsvFormatError& e) {
    throw CurveFormatError(e.source(), e.line(), e.column(), e.reason());
  }
}

}  // namespace puncture::validation
