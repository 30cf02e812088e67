#include <puncture/io/csv_table.hpp>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#include <puncture/io/csv_reader.hpp>
#include <puncture/io/csv_writer.hpp>
#include <puncture/io/output_session.hpp>

namespace puncture::io {

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

void CsvTable::add_metadata(const std::string& key, const std::string& value) { metadata_.emplace_back(key, value); }

void CsvTable::add_provenance(const Provenance& provenance) {
  for (const auto& kv : provenance_fields(provenance)) metadata_.push_back(kv);
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
  CsvWriter w(columns_);
  for (const auto& [k, v] : metadata_) w.add_metadata(k, v);
  for (const auto& r : rows_) {
    for (double x : r) w.number(x);
    w.end_row();
  }
  return w.str();
}

namespace {
bool parse_any_double(const std::string& f, double& v) {
  if (f == "nan" || f == "-nan") return v = std::numeric_limits<double>::quiet_NaN(), true;
  if (f == "inf") return v = std::numeric_limits<double>::infinity(), true;
  if (f == "-inf") return v = -std::numeric_limits<double>::infinity(), true;
  return parse_finite_number(f, v);
}
}  // namespace

CsvTable CsvTable::parse(const std::string& text) {
  CsvDocument doc;
  try {
    doc = parse_csv(text, "CsvTable::parse");
  } catch (const CsvFormatError& e) {
    throw std::invalid_argument(e.what());
  }
  CsvTable table(doc.header);
  table.metadata_ = doc.metadata;
  for (const CsvRecord& r : doc.records) {
    std::vector<double> values(r.fields.size());
    for (std::size_t c = 0; c < r.fields.size(); ++c)
      if (!parse_any_double(r.fields[c], values[c]))
        throw std::invalid_argument("CsvTable::parse: line " + std::to_string(r.line) + ", column '" +
                                    doc.header[c] + "': '" + r.fields[c] + "' is not a number");
    table.add_row(values);
  }
  return table;
}

void write_csv(OutputSession& session, const std::string& relative_name, const CsvTable& table) {
  session.write_text(relative_name, table.to_string());
}

}  // namespace puncture::io
