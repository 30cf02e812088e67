// The one CSV reader and writer: provenance header, quoting, exact number
// round trips, and errors that name source, line and column.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "puncture/io/csv_reader.hpp"
#include "puncture/io/csv_table.hpp"
#include "puncture/io/csv_writer.hpp"

namespace puncture::io {
namespace {

Provenance sample_provenance() {
  return {"puncture run scenes/default.json -o out/x", "0.1.0", "abc1234", "2026-01-02T03:04:05Z", "host (cpu, 2 cores)"};
}

TEST(CsvWriter, ProvenanceHeaderThenTableReadBackByTheReader) {
  CsvWriter w({"name", "value", "count"});
  w.add_provenance(sample_provenance());
  w.add_metadata("speed_mm_per_s", "10");
  w.text("skin, outer").number(0.1).integer(3).end_row();
  w.text("say \"hi\"").number(-2.5e-300).integer(-7).end_row();
  const std::string text = w.str();
  EXPECT_EQ(text.rfind("# command: puncture run scenes/default.json -o out/x\n# program_version: 0.1.0\n"
                       "# git_revision: abc1234\n# date_utc: 2026-01-02T03:04:05Z\n# machine: host (cpu, 2 cores)\n"
                       "# speed_mm_per_s: 10\nname,value,count\n",
                       0),
            0u)
      << text;

  const CsvDocument doc = parse_csv(text, "mem.csv");
  ASSERT_EQ(doc.metadata.size(), 6u);
  EXPECT_EQ(doc.metadata[0].first, "command");
  EXPECT_EQ(*doc.metadata_value("git_revision"), "abc1234");
  EXPECT_EQ(*doc.metadata_value("speed_mm_per_s"), "10");
  EXPECT_EQ(doc.header, (std::vector<std::string>{"name", "value", "count"}));
  ASSERT_EQ(doc.records.size(), 2u);
  EXPECT_EQ(doc.records[0].fields[0], "skin, outer");
  EXPECT_EQ(doc.records[1].fields[0], "say \"hi\"");
  EXPECT_EQ(doc.number(doc.records[0], 1), 0.1);        // shortest round trip: bit-exact
  EXPECT_EQ(doc.number(doc.records[1], 1), -2.5e-300);
  EXPECT_EQ(doc.records[1].line, 9);  // 6 metadata lines, header, two records
}

TEST(CsvWriter, RowsMustBeComplete) {
  CsvWriter w({"a", "b"});
  w.number(1);
  EXPECT_THROW(w.end_row(), std::logic_error);
  EXPECT_THROW(w.str(), std::logic_error);
  EXPECT_THROW(CsvWriter({"a", "a"}), std::invalid_argument);
  EXPECT_THROW(w.add_metadata("two words", "x"), std::invalid_argument);
  EXPECT_EQ(csv_number(std::numeric_limits<double>::quiet_NaN()), "nan");
  EXPECT_EQ(csv_number(-std::numeric_limits<double>::infinity()), "-inf");
  EXPECT_EQ(csv_number(1.0 / 3.0, 4), "0.3333");
}

TEST(CsvReader, ErrorsNameSourceLineAndColumn) {
  try {
    const CsvDocument doc = parse_csv("# a: b\nx,y\n1,2\n3\n", "curve.csv");
    FAIL() << "accepted a short record";
  } catch (const CsvFormatError& e) {
    EXPECT_EQ(e.line(), 4);
    EXPECT_NE(std::string(e.what()).find("curve.csv:4: expected 2 fields, got 1"), std::string::npos) << e.what();
  }
  const CsvDocument doc = parse_csv("x,y\n1,abc\n", "c.csv");
  try {
    doc.number(doc.records[0], 1);
    FAIL();
  } catch (const CsvFormatError& e) {
    EXPECT_EQ(std::string(e.what()), "c.csv:2: column 'y': not a finite number: 'abc'");
  }
  EXPECT_THROW(parse_csv("", "empty.csv"), CsvFormatError);
  EXPECT_THROW(parse_csv("a,a\n", "dup.csv"), CsvFormatError);
  EXPECT_THROW(parse_csv("a,b\n\"open,1\n", "quote.csv"), CsvFormatError);
  EXPECT_THROW(doc.require_column("z"), CsvFormatError);
  double v = 0;
  EXPECT_FALSE(parse_finite_number("1e400", v));
  EXPECT_FALSE(parse_finite_number("nan", v));
  EXPECT_FALSE(parse_finite_number("1.5x", v));
  EXPECT_FALSE(parse_finite_number("", v));
  EXPECT_TRUE(parse_finite_number("-1.5e-3", v));
  EXPECT_EQ(v, -1.5e-3);
}

TEST(CsvReader, QuotedFieldsMaySpanLinesAndCommentsAreSkipped) {
  const CsvDocument doc = parse_csv("a,b\r\n\"two\nlines\", 5 \n# a comment between records\n\n x ,6\n", "q.csv");
  ASSERT_EQ(doc.records.size(), 2u);
  EXPECT_EQ(doc.records[0].fields[0], "two\nlines");
  EXPECT_EQ(doc.records[0].fields[1], "5");  // unquoted fields are trimmed
  EXPECT_EQ(doc.records[1].fields[0], "x");
  EXPECT_EQ(doc.records[1].line, 6);
  EXPECT_TRUE(doc.metadata.empty());
}

TEST(CsvTable, ProvenanceAndNonFiniteValuesRoundTrip) {
  CsvTable t({"time_s", "force_N"});
  t.add_provenance(sample_provenance());
  t.add_row({0.1, std::numeric_limits<double>::infinity()});
  t.add_row({1e-17, std::numeric_limits<double>::quiet_NaN()});
  const CsvTable back = CsvTable::parse(t.to_string());
  EXPECT_EQ(back.metadata(), t.metadata());
  EXPECT_EQ(back.row(0)[0], 0.1);
  EXPECT_TRUE(std::isinf(back.row(0)[1]));
  EXPECT_EQ(back.row(1)[0], 1e-17);
  EXPECT_TRUE(std::isnan(back.row(1)[1]));
}

}  // namespace
}  // namespace puncture::io
