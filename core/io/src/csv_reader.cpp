#include "puncture/io/csv_reader.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>

#include "puncture/io/atomic_file.hpp"

namespace puncture::io {

CsvFormatError::CsvFormatError(const std::string& source, int line, const std::string& column, const std::string& what)
    : std::runtime_error(source + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " +
                         (column.empty() ? std::string() : "column '" + column + "': ") + what),
      source_(source),
      line_(line),
      column_(column),
      reason_(what) {}

namespace {

std::string trim(const std::string& s) {
  const char* ws = " \t\r";
  const auto a = s.find_first_not_of(ws);
  if (a == std::string::npos) return {};
  const auto b = s.find_last_not_of(ws);
  return s.substr(a, b - a + 1);
}

/// One physical line starting at pos (without its '\n'); advances pos.
std::string next_line(const std::string& text, std::size_t& pos) {
  const std::size_t end = text.find('\n', pos);
  std::string line = text.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
  pos = end == std::string::npos ? text.size() : end + 1;
  return line;
}

/// Splits one record starting at pos (quoted fields may span lines); advances
/// pos and line past it.
std::vector<std::string> split_record(const std::string& text, std::size_t& pos, int& line, const std::string& source) {
  const int first_line = line;
  std::vector<std::string> fields;
  std::string field;
  bool quoted = false, was_quoted = false;
  auto finish_field = [&] {
    fields.push_back(was_quoted ? field : trim(field));
    field.clear();
    was_quoted = false;
  };
  while (pos < text.size()) {
    const char c = text[pos++];
    if (quoted) {
      if (c == '"') {
        if (pos < text.size() && text[pos] == '"') {
          field += '"';
          ++pos;
        } else {
          quoted = false;
        }
      } else {
        if (c == '\n') ++line;
        field += c;
      }
    } else if (c == '"' && trim(field).empty() && !was_quoted) {
      field.clear();
      quoted = was_quoted = true;
    } else if (c == ',') {
      finish_field();
    } else if (c == '\n') {
      ++line;
      finish_field();
      return fields;
    } else if (was_quoted) {
      if (c != ' ' && c != '\t' && c != '\r')
        throw CsvFormatError(source, line, "", "text after a closing quote");
    } else {
      field += c;
    }
  }
  if (quoted) throw CsvFormatError(source, first_line, "", "unterminated quote");
  ++line;
  finish_field();
  return fields;
}

}  // namespace

int CsvDocument::column(const std::string& name) const {
  for (std::size_t j = 0; j < header.size(); ++j)
    if (header[j] == name) return static_cast<int>(j);
  return -1;
}

std::size_t CsvDocument::require_column(const std::string& name) const {
  const int j = column(name);
  if (j < 0) throw CsvFormatError(source, header_line, name, "required column missing from the header");
  return static_cast<std::size_t>(j);
}

const std::string* CsvDocument::metadata_value(const std::string& key) const {
  const std::string* found = nullptr;
  for (const auto& [k, v] : metadata)
    if (k == key) found = &v;
  return found;
}

double CsvDocument::number(const CsvRecord& record, std::size_t column) const {
  double v = 0.0;
  if (!parse_finite_number(record.fields.at(column), v))
    throw CsvFormatError(source, record.line, header.at(column),
                         "not a finite number: '" + record.fields[column] + "'");
  return v;
}

std::map<std::string, std::string> CsvDocument::metadata_map() const {
  std::map<std::string, std::string> out;
  for (const auto& [k, v] : metadata) out[k] = v;
  return out;
}

bool parse_finite_number(const std::string& text, double& value) {
  if (text.empty() || text.front() == ' ' || text.front() == '\t') return false;
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  // ERANGE on underflow (subnormal or 0) is fine; overflow gives inf and is rejected.
  if (end != text.c_str() + text.size() || !std::isfinite(v)) return false;
  value = v;
  return true;
}

CsvDocument parse_csv(const std::string& text, const std::string& source) {
  CsvDocument doc;
  doc.source = source;
  std::size_t pos = 0;
  int line = 1;
  while (pos < text.size()) {
    const std::size_t line_start = pos;
    const int this_line = line;
    std::size_t probe = pos;
    const std::string raw = next_line(text, probe);
    const std::string t = trim(raw);
    if (t.empty()) {
      pos = probe, ++line;
      continue;
    }
    if (t[0] == '#') {
      pos = probe, ++line;
      if (!doc.header.empty()) continue;  // a comment between records
      const std::string body = trim(t.substr(1));
      const auto colon = body.find(':');
      if (colon != std::string::npos && colon > 0) {
        const std::string key = trim(body.substr(0, colon));
        if (key.find_first_of(" \t") == std::string::npos) doc.metadata.emplace_back(key, trim(body.substr(colon + 1)));
      }
      continue;
    }
    pos = line_start;
    std::vector<std::string> fields = split_record(text, pos, line, source);
    if (doc.header.empty()) {
      doc.header_line = this_line;
      for (std::size_t j = 0; j < fields.size(); ++j) {
        if (fields[j].empty())
          throw CsvFormatError(source, this_line, "", "empty column name in header (column " + std::to_string(j + 1) + ")");
        for (std::size_t k = 0; k < j; ++k)
          if (fields[k] == fields[j]) throw CsvFormatError(source, this_line, fields[j], "duplicate column name");
      }
      doc.header = std::move(fields);
      continue;
    }
    if (fields.size() != doc.header.size())
      throw CsvFormatError(source, this_line, "",
                           "expected " + std::to_string(doc.header.size()) + " fields, got " + std::to_string(fields.size()));
    doc.records.push_back({this_line, std::move(fields)});
  }
  if (doc.header.empty()) throw CsvFormatError(source, 0, "", "no header line");
  return doc;
}

CsvDocument read_csv_file(const std::filesystem::path& path) {
  return parse_csv(read_text_file(path), path.string());
}

}  // namespace puncture::io
