// csv_table.hpp: a table of doubles with named columns, written as CSV.
//
// Format: the writer's (csv_writer.hpp): metadata lines "# key: value" (the
// provenance, when set), the column names (quoted if needed), then one line
// per row. Doubles are printed in the shortest form that reads back to the
// same bits (std::to_chars), so a written table parses back exactly.
// Non-finite values print as nan / inf / -inf and parse back.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "puncture/io/provenance.hpp"

namespace puncture::io {

class OutputSession;

class CsvTable {
 public:
  CsvTable() = default;
  explicit CsvTable(std::vector<std::string> column_names);

  /// Appends a column. Throws std::logic_error once rows exist,
  /// std::invalid_argument for an empty or duplicate name.
  void add_column(const std::string& name);
  /// Appends a row; values.size() must equal n_columns() (std::invalid_argument otherwise).
  void add_row(const std::vector<double>& values);

  /// Metadata lines written before the header ("# key: value").
  void add_metadata(const std::string& key, const std::string& value);
  /// The provenance fields as metadata.
  void add_provenance(const Provenance& provenance);
  const std::vector<std::pair<std::string, std::string>>& metadata() const { return metadata_; }

  std::size_t n_columns() const { return columns_.size(); }
  std::size_t n_rows() const { return rows_.size(); }
  const std::vector<std::string>& column_names() const { return columns_; }
  const std::vector<double>& row(std::size_t i) const { return rows_.at(i); }
  /// Index of a named column; throws std::out_of_range if absent.
  std::size_t column_index(const std::string& name) const;
  /// All values of one column, row order.
  std::vector<double> column(const std::string& name) const;

  std::string to_string() const;
  /// Parses text written by to_string() (or any CSV of csv_reader.hpp's
  /// format whose fields are numbers, nan or inf); metadata lines are kept.
  /// Throws std::invalid_argument naming the line on a malformed line.
  static CsvTable parse(const std::string& text);

 private:
  std::vector<std::string> columns_;
  std::vector<std::vector<double>> rows_;
  std::vector<std::pair<std::string, std::string>> metadata_;
};

/// session.write_text(relative_name, table.to_string()).
void write_csv(OutputSession& session, const std::string& relative_name, const CsvTable& table);

}  // namespace puncture::io
