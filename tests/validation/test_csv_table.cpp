// CsvTable: round trip to the same bits, quoting of header names, errors.
#include <puncture/io/csv_table.hpp>
#include <puncture/io/output_session.hpp>

#include "test_io_common.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace {

using puncture::io::CsvTable;

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

TEST(CsvTable, RoundTripIsBitExact) {
  CsvTable table({"depth_m", "force_N", "name, with \"comma\""});
  const double tricky[] = {0.1, 1.0 / 3.0, -0.0, 5e-324, std::numeric_limits<double>::max(),
                           1e-300, -2.5e17, 123456789.123456789, std::nextafter(1.0, 2.0)};
  for (double x : tricky) table.add_row({x, -x, x * 3});
  table.add_row({std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(), 0});
  const std::string text = table.to_string();
  EXPECT_EQ(text.substr(0, text.find('\n')), "depth_m,force_N,\"name, with \"\"comma\"\"\"");

  const CsvTable back = CsvTable::parse(text);
  ASSERT_EQ(back.column_names(), table.column_names());
  ASSERT_EQ(back.n_rows(), table.n_rows());
  for (std::size_t r = 0; r < table.n_rows(); ++r)
    for (std::size_t c = 0; c < table.n_columns(); ++c)
      EXPECT_TRUE(same_bits(back.row(r)[c], table.row(r)[c]))
          << "row " << r << " column " << c << ": " << back.row(r)[c] << " vs " << table.row(r)[c];
  EXPECT_EQ(back.column("force_N")[0], -0.1);
}

TEST(CsvTable, ThroughAnOutputSessionFile) {
  puncture::io::testing::ScratchDir scratch;
  CsvTable table({"t_s", "F_N"});
  table.add_row({0.0, 0.0});
  table.add_row({0.001, 0.0421});
  {
    puncture::io::OutputSession session(scratch.path());
    puncture::io::write_csv(session, "force.csv", table);
    session.commit();
  }
  const CsvTable back = CsvTable::parse(puncture::io::testing::read_file(scratch.path() / "force.csv"));
  EXPECT_EQ(back.column("F_N"), (std::vector<double>{0.0, 0.0421}));
}

TEST(CsvTable, RejectsMisuseAndMalformedText) {
  CsvTable table({"a", "b"});
  EXPECT_THROW(table.add_row({1.0}), std::invalid_argument);
  EXPECT_THROW(table.add_column("a"), std::invalid_argument);
  EXPECT_THROW(table.add_column(""), std::invalid_argument);
  table.add_row({1.0, 2.0});
  EXPECT_THROW(table.add_column("c"), std::logic_error);
  EXPECT_THROW(table.column_index("missing"), std::out_of_range);
  EXPECT_THROW(CsvTable::parse(""), std::invalid_argument);
  EXPECT_THROW(CsvTable::parse("a,b\n1\n"), std::invalid_argument);
  EXPECT_THROW(CsvTable::parse("a,b\n1,x2\n"), std::invalid_argument);
  EXPECT_THROW(CsvTable::parse("a,b\n1,2.5abc\n"), std::invalid_argument);
  EXPECT_THROW(CsvTable::parse("\"a,b\n1,2\n"), std::invalid_argument);
  // CRLF line ends are accepted.
  const CsvTable crlf = CsvTable::parse("a,b\r\n1,2\r\n");
  EXPECT_EQ(crlf.row(0), (std::vector<double>{1.0, 2.0}));
}

}  // namespace
