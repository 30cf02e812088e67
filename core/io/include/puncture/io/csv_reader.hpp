// csv_reader.hpp: the one CSV reader of the project (insertion curves, FEM
// profiles, score tables, tables written by csv_table.hpp / csv_writer.hpp).
//
// Format (RFC 4180 subset, separator ','):
//   * lines starting with '#' before the header are comments; those of the
//     form "# key: value" (key without spaces) are kept as metadata, in file
//     order (the provenance header of every CSV the project writes);
//   * the first other non-blank line is the header (column names);
//   * then one record per line; blank lines and '#' lines are skipped; a field
//     may be quoted ("..." with "" for a quote, and may then hold ',' or line
//     breaks); unquoted fields are trimmed of spaces, tabs and '\r';
//   * every record must have as many fields as the header.
// Errors throw CsvFormatError naming source, line and column.
#pragma once

#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace puncture::io {

class CsvFormatError : public std::runtime_error {
 public:
  /// Message: "<source>[:<line>]: [column '<column>': ]<what>".
  CsvFormatError(const std::string& source, int line, const std::string& column, const std::string& what);
  const std::string& source() const { return source_; }
  int line() const { return line_; }  ///< 1-based, 0 when not tied to a line
  const std::string& column() const { return column_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string source_;
  int line_;
  std::string column_;
  std::string reason_;
};

struct CsvRecord {
  int line = 0;                     ///< 1-based line where the record starts
  std::vector<std::string> fields;  ///< one per header column
};

struct CsvDocument {
  std::string source;                                          ///< file name or description (messages)
  std::vector<std::pair<std::string, std::string>> metadata;   ///< "# key: value" lines before the header
  std::vector<std::string> header;
  int header_line = 0;
  std::vector<CsvRecord> records;

  /// Column index, -1 if absent.
  int column(const std::string& name) const;
  /// Column index; throws CsvFormatError("required column missing") if absent.
  std::size_t require_column(const std::string& name) const;
  /// Metadata value or nullptr.
  const std::string* metadata_value(const std::string& key) const;
  /// Field of a record as a finite number; throws CsvFormatError naming line and column.
  double number(const CsvRecord& record, std::size_t column) const;
  /// Metadata as a map (later keys win).
  std::map<std::string, std::string> metadata_map() const;
};

/// Parses CSV text. Throws CsvFormatError for an empty text (no header), an
/// empty or duplicate column name, a record with the wrong field count, or an
/// unterminated quote.
CsvDocument parse_csv(const std::string& text, const std::string& source);

/// read_text_file(path) + parse_csv (source = path).
CsvDocument read_csv_file(const std::filesystem::path& path);

/// Whole-field decimal number (strtod syntax, surrounding blanks not allowed).
/// False for an empty field, trailing characters, overflow or a non-finite value.
bool parse_finite_number(const std::string& text, double& value);

}  // namespace puncture::io
