// csv_table.hpp: a table of doubles with named columns, written as CSV.
//
// Format (RFC 4180 subset): first line the column names (quoted with "..." if
// a name holds a comma, quote or line break; quotes doubled), then one line per
// row; separator ',', line end '\n'. Doubles are printed in the shortest form
// that reads back to the same bits (std::to_chars), so a written table parses
// back exactly. Non-finite values print as nan / inf / -inf.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

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

  std::size_t n_columns() const { return columns_.size(); }
  std::size_t n_rows() const { return rows_.size(); }
  const std::vector<std::string>& column_names() const { return columns_; }
  const std::vector<double>& row(std::size_t i) const { return rows_.at(i); }
  /// Index of a named column; throws std::out_of_range if absent.
  std::size_t column_index(const std::string& name) const;
  /// All values of one column, row order.
  std::vector<double> column(const std::string& name) const;

  std::string to_string() const;
  /// Parses text written by to_string() (or any CSV of this subset whose
  /// fields after the header are numbers). Throws std::invalid_argument with
  /// the line number on a malformed line.
  static CsvTable parse(const std::string& text);

 private:
  std::vector<std::string> columns_;
  std::vector<std::vector<double>> rows_;
};

/// session.write_text(relative_name, table.to_string()).
void write_csv(OutputSession& session, const std::string& relative_name, const CsvTable& table);

}  // namespace puncture::io
