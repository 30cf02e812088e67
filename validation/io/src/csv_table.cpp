#include <puncture/io/csv_table.hpp>

#include <puncture/io/output_session.hpp>

#include <algorithm>
#include <charconv>
#include <stdexcept>

namespace puncture::io {

namespace {

std::string quote_if_needed(const std::string& field) {
  if (field.find_first_of(",\"\r\n") == std::string::npos) return field;
  std::string out = "\"";
  for (char c : field) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

/// Splits one CSV record starting at `pos` (handles quoted fields); advances
/// pos past the record's line end. Returns false at end of text.
bool next_record(const std::string& text, std::size_t& pos, std::vector<std::string>& fields,
                 std::size_t& line) {
  fields.clear();
  if (pos >= text.size()) return false;
  std::string field;
  bool quoted = false;
  bool field_was_quoted = false;
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
    } else if (c == '"' && field.empty() && !field_was_quoted) {
      quoted = field_was_quoted = true;
    } else if (c == ',') {
      fields.push_back(field);
      field.clear();
      field_was_quoted = false;
    } else if (c == '\n') {
      fields.push_back(field);
      ++line;
      return true;
    } else if (c != '\r') {
      field += c;
    }
  }
  if (quoted) throw std::invalid_argument("CsvTable::parse: unterminated quote at line " + std::to_string(line));
  fields.push_back(field);
  return true;
}

}  // namespace

CsvTable::CsvTable(std::vector<std::string> column_names) {
  for (const auto& name : column_names) add_column(name);
}

void CsvTable::add_column(const std::string& name) {
  if (!rows_.empty()) throw std::logic_error("CsvTable::add_column('" + name + "') after rows were added");
  if (name.empty()) throw std::invalid_argument("CsvTable::add_column: empty column name");
  if (std::find(columns_.begin(), columns_.end(), name) != columns_.end())
    throw std::invalid_argument("CsvTable::add_column: duplicate column '" + name + "'");
  columns_.push_back(name);
}

void CsvTable::add_row(const std::vector<double>& values) {
  if (values.size() != columns_.size())
    throw std::invalid_argument("CsvTable::add_row: " + std::to_string(values.size()) +
                                " values for " + std::to_string(columns_.size()) + " columns");
  rows_.push_back(values);
}

std::size_t CsvTable::column_index(const std::string& name) const {
  const auto it = std::find(columns_.begin(), columns_.end(), name);
  if (it == columns_.end()) throw std::out_of_range("CsvTable: no column '" + name + "'");
  return static_cast<std::size_t>(it - columns_.begin());
}

std::vector<double> CsvTable::column(const std::string& name) const {
  const std::size_t c = column_index(name);
  std::vector<double> out;
  out.reserve(rows_.size());
  for (const auto& r : rows_) out.push_back(r[c]);
  return out;
}

std::string CsvTable::to_string() const {
  std::string out;
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    if (c) out += ',';
    out += quote_if_needed(columns_[c]);
  }
  out += '\n';
  char buffer[64];
  for (const auto& r : rows_) {
    for (std::size_t c = 0; c < r.size(); ++c) {
      if (c) out += ',';
      const auto res = std::to_chars(buffer, buffer + sizeof(buffer), r[c]);  // shortest round trip
      out.append(buffer, res.ptr);
    }
    out += '\n';
  }
  return out;
}

CsvTable CsvTable::parse(const std::string& text) {
  std::size_t pos = 0, line = 1;
  std::vector<std::string> fields;
  if (!next_record(text, pos, fields, line)) throw std::invalid_argument("CsvTable::parse: empty text");
  CsvTable table(fields);
  while (true) {
    const std::size_t record_line = line;
    if (!next_record(text, pos, fields, line)) break;
    if (fields.size() == 1 && fields[0].empty()) continue;  // blank line
    if (fields.size() != table.n_columns())
      throw std::invalid_argument("CsvTable::parse: line " + std::to_string(record_line) + " has " +
                                  std::to_string(fields.size()) + " fields, header has " +
                                  std::to_string(table.n_columns()));
    std::vector<double> values(fields.size());
    for (std::size_t c = 0; c < fields.size(); ++c) {
      const std::string& f = fields[c];
      const auto res = std::from_chars(f.data(), f.data() + f.size(), values[c]);
      if (res.ec != std::errc() || res.ptr != f.data() + f.size())
        throw std::invalid_argument("CsvTable::parse: line " + std::to_string(record_line) +
                                    ", column '" + table.columns_[c] + "': '" + f +
                                    "' is not a number");
    }
    table.add_row(values);
  }
  return table;
}

void write_csv(OutputSession& session, const std::string& relative_name, const CsvTable& table) {
  session.write_text(relative_name, table.to_string());
}

}  // namespace puncture::io
