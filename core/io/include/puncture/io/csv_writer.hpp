// csv_writer.hpp: the one CSV writer of the project, for tables whose
// columns mix text and numbers (CsvTable in csv_table.hpp holds numbers only
// and writes through the same rules).
//
// Output: metadata lines "# key: value" (the provenance first, when given),
// the header line, then one line per row; separator ',', line end '\n'.
// Text fields are quoted ("...", quotes doubled) only when they hold ',', '"'
// or a line break. Numbers print in the shortest form that reads back to the
// same double (std::to_chars); non-finite numbers print as nan / inf / -inf.
// The reader of csv_reader.hpp reads every file this writes.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "puncture/io/provenance.hpp"

namespace puncture::io {

/// Field text quoted if it holds ',', '"', '\r' or '\n'.
std::string csv_quote(const std::string& field);
/// Shortest round-trip text of a double ("nan", "inf", "-inf" for non-finite).
std::string csv_number(double value);
/// Fixed number of significant digits (for tables read by people), "nan"/"inf" for non-finite.
std::string csv_number(double value, int significant_digits);

class CsvWriter {
 public:
  /// Throws std::invalid_argument for an empty or duplicate column name.
  explicit CsvWriter(std::vector<std::string> columns);

  /// Adds the provenance lines (command, version, git revision, date,
  /// machine) to the metadata; call before any other metadata to have them first.
  void add_provenance(const Provenance& provenance);
  /// "# key: value" line before the header (key without spaces or ':';
  /// line breaks in value become spaces). Throws std::invalid_argument for a bad key.
  void add_metadata(const std::string& key, const std::string& value);

  CsvWriter& text(const std::string& value);
  CsvWriter& number(double value);
  CsvWriter& number(double value, int significant_digits);
  CsvWriter& integer(long long value);
  /// Ends the current row; throws std::logic_error unless it has one field per column.
  void end_row();

  std::size_t n_rows() const { return rows_; }
  std::size_t n_columns() const { return n_columns_; }
  /// The whole document (metadata, header, rows). Throws std::logic_error inside a row.
  std::string str() const;

 private:
  void field(const std::string& text);
  std::string metadata_;
  std::string head_;
  std::string body_;
  std::size_t n_columns_ = 0;
  std::size_t fields_in_row_ = 0;
  std::size_t rows_ = 0;
};

}  // namespace puncture::io
