#include "puncture/io/csv_writer.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace puncture::io {

std::string csv_quote(const std::string& field) {
  if (field.find_first_of(",\"\r\n") == std::string::npos) return field;
  std::string out = "\"";
  for (char c : field) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string csv_number(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[64];
  const auto res = std::to_chars(buffer, buffer + sizeof(buffer), value);  // shortest round trip
  return std::string(buffer, res.ptr);
}

std::string csv_number(double value, int significant_digits) {
  if (!std::isfinite(value)) return csv_number(value);
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*g", std::clamp(significant_digits, 1, 17), value);
  return buffer;
}

CsvWriter::CsvWriter(std::vector<std::string> columns) : n_columns_(columns.size()) {
  for (std::size_t j = 0; j < columns.size(); ++j) {
    if (columns[j].empty()) throw std::invalid_argument("CsvWriter: empty column name");
    for (std::size_t k = 0; k < j; ++k)
      if (columns[k] == columns[j]) throw std::invalid_argument("CsvWriter: duplicate column '" + columns[j] + "'");
    head_ += (j ? "," : "") + csv_quote(columns[j]);
  }
  head_ += '\n';
}

void CsvWriter::add_provenance(const Provenance& provenance) {
  for (const auto& [key, value] : provenance_fields(provenance)) add_metadata(key, value);
}

void CsvWriter::add_metadata(const std::string& key, const std::string& value) {
  if (key.empty() || key.find_first_of(" \t:\r\n") != std::string::npos)
    throw std::invalid_argument("CsvWriter::add_metadata: bad key '" + key + "'");
  std::string v = value;
  for (char& c : v)
    if (c == '\n' || c == '\r') c = ' ';
  metadata_ += "# " + key + ": " + v + "\n";
}

void CsvWriter::field(const std::string& text) {
  if (fields_in_row_ > 0) body_ += ',';
  body_ += text;
  ++fields_in_row_;
}

CsvWriter& CsvWriter::text(const std::string& value) {
  field(csv_quote(value));
  return *this;
}
CsvWriter& CsvWriter::number(double value) {
  field(csv_number(value));
  return *this;
}
CsvWriter& CsvWriter::number(double value, int significant_digits) {
  field(csv_number(value, significant_digits));
  return *this;
}
CsvWriter& CsvWriter::integer(long long value) {
  field(std::to_string(value));
  return *this;
}

void CsvWriter::end_row() {
  if (fields_in_row_ != n_columns_)
    throw std::logic_error("CsvWriter::end_row: " + std::to_string(fields_in_row_) + " fields for " +
                           std::to_string(n_columns_) + " columns");
  body_ += '\n';
  fields_in_row_ = 0;
  ++rows_;
}

std::string CsvWriter::str() const {
  if (fields_in_row_ != 0) throw std::logic_error("CsvWriter::str: a row is not finished");
  return metadata_ + head_ + body_;
}

}  // namespace puncture::io
