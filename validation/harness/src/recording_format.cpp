// The format of a raw rig recording (recording.hpp): the JSON sidecar, the
// command line's fields over it, the units (s, m, N per unit of the file) and
// the checks, every error naming the file and the field.
#include <nlohmann/json.hpp>

#include <cmath>
#include <utility>
#include <vector>

#include "puncture/io/atomic_file.hpp"
#include "puncture/validation/recording.hpp"

namespace puncture::validation {

RecordingError::RecordingError(const std::string& file, const std::string& field, const std::string& what)
    : ReferenceError(file + ": " + (field.empty() ? std::string() : "field '" + field + "': ") + what) {}

bool RecordingFormat::empty() const {
  return time.name.empty() && time.unit.empty() && position.name.empty() && position.unit.empty() &&
         force.name.empty() && force.unit.empty() && into_tissue == StageDirection::Unset && force_sign == 0;
}

namespace {

using Json = nlohmann::json;

std::string text_field(const Json& j, const std::string& source, const std::string& field) {
  if (!j.is_string() || j.get<std::string>().empty())
    throw RecordingError(source, field, "must be a non-empty string");
  return j.get<std::string>();
}

/// One of "time", "position", "force": its column, unit and (position,
/// force) its direction or sign; unknown keys are errors.
void parse_column(const Json& j, const std::string& source, const std::string& key, RecordingFormat& f) {
  if (!j.is_object()) throw RecordingError(source, key, "must be an object with \"column\" (and \"unit\")");
  RecordingColumn& c = key == "time" ? f.time : key == "position" ? f.position : f.force;
  for (const auto& [name, value] : j.items()) {
    const std::string field = key + "." + name;
    if (name == "column") {
      c.name = text_field(value, source, field);
    } else if (name == "unit") {
      c.unit = text_field(value, source, field);
    } else if (name == "into_tissue" && key == "position") {
      const std::string d = text_field(value, source, field);
      if (d != "increasing" && d != "decreasing")
        throw RecordingError(source, field, "must be \"increasing\" or \"decreasing\" (got \"" + d + "\")");
      f.into_tissue = d == "increasing" ? StageDirection::Increasing : StageDirection::Decreasing;
    } else if (name == "sign" && key == "force") {
      if (!value.is_number() || (value.get<double>() != 1.0 && value.get<double>() != -1.0))
        throw RecordingError(source, field, "must be 1 or -1 (the sign of the file's force while the tissue resists)");
      f.force_sign = value.get<double>() > 0.0 ? 1 : -1;
    } else {
      throw RecordingError(source, field, "unknown key");
    }
  }
}

/// Unit suffix of a column name ("t_us" -> "us"), empty without one.
std::string unit_suffix(const std::string& name) {
  const std::size_t at = name.rfind('_');
  return at == std::string::npos ? std::string() : name.substr(at + 1);
}

}  // namespace

RecordingFormat parse_recording_format(const std::string& json_text, const std::string& source) {
  Json j;
  try {
    j = Json::parse(json_text);
  } catch (const Json::parse_error& e) {
    throw RecordingError(source, "", std::string("not valid JSON: ") + e.what());
  }
  if (!j.is_object()) throw RecordingError(source, "", "must be a JSON object with time, position and force");
  RecordingFormat f;
  f.source = source;
  for (const auto& [key, value] : j.items()) {
    if (key == "time" || key == "position" || key == "force") parse_column(value, source, key, f);
    else if (key != "description") throw RecordingError(source, key, "unknown key (time, position, force, description)");
  }
  return f;
}

RecordingFormat read_recording_format(const std::filesystem::path& path) {
  std::string text;
  try {
    text = io::read_text_file(path);
  } catch (const std::runtime_error& e) {
    throw RecordingError(path.string(), "", e.what());
  }
  return parse_recording_format(text, path.string());
}

RecordingFormat merge_recording_formats(const RecordingFormat& base, const RecordingFormat& o) {
  RecordingFormat f = base;
  auto take = [](RecordingColumn& into, const RecordingColumn& from) {
    if (!from.name.empty()) into.name = from.name;
    if (!from.unit.empty()) into.unit = from.unit;
  };
  take(f.time, o.time);
  take(f.position, o.position);
  take(f.force, o.force);
  if (o.into_tissue != StageDirection::Unset) f.into_tissue = o.into_tissue;
  if (o.force_sign != 0) f.force_sign = o.force_sign;
  if (base.empty()) f.source = o.source;
  else if (!o.empty()) f.source = base.source + " and " + o.source;
  return f;
}

double unit_factor(const RecordingFormat& format, const RecordingColumn& column, const std::string& field,
                   const char* quantity) {
  using Units = std::vector<std::pair<const char*, double>>;
  static const Units kTime{{"s", 1.0}, {"ms", 1e-3}, {"us", 1e-6}};
  static const Units kLength{{"m", 1.0}, {"mm", 1e-3}, {"um", 1e-6}};
  static const Units kForce{{"N", 1.0}, {"mN", 1e-3}};
  const std::string q = quantity;
  const Units& table = q == "time" ? kTime : q == "position" ? kLength : kForce;
  const std::string unit = column.unit.empty() ? unit_suffix(column.name) : column.unit;
  std::string known;
  for (const auto& [name, factor] : table) {
    if (unit == name) return factor;
    known += (known.empty() ? "" : ", ") + std::string(name);
  }
  if (column.unit.empty())
    throw RecordingError(format.source, field, "missing, and the column name '" + column.name +
                                                   "' does not end in a known unit (_" + known + ")");
  throw RecordingError(format.source, field, "unknown " + q + " unit '" + unit + "' (" + known + ")");
}

void check_recording_format(const RecordingFormat& f) {
  const std::pair<const RecordingColumn*, const char*> columns[] = {
      {&f.time, "time"}, {&f.position, "position"}, {&f.force, "force"}};
  for (const auto& [c, key] : columns) {
    if (c->name.empty()) throw RecordingError(f.source, std::string(key) + ".column", std::string("missing: the CSV column of the ") + key);
    unit_factor(f, *c, std::string(key) + ".unit", key);
  }
  if (f.into_tissue == StageDirection::Unset)
    throw RecordingError(f.source, "position.into_tissue",
                         "missing: \"increasing\" or \"decreasing\" (the stage position as the needle goes in)");
  if (f.force_sign == 0)
    throw RecordingError(f.source, "force.sign", "missing: 1 or -1 (the sign of the file's force while the tissue resists)");
}

std::filesystem::path recording_sidecar_path(const std::filesystem::path& csv) {
  std::filesystem::path p = csv;
  return p.replace_extension(".json");
}

}  // namespace puncture::validation
