// csv_header.hpp: reads past the provenance lines ("# key: value") that open
// every CSV the program writes, returning the header line; fails the test if
// the provenance is missing.
#pragma once

#include <gtest/gtest.h>

#include <istream>
#include <string>

namespace puncture::apps::test {

inline std::string header_after_provenance(std::istream& in) {
  std::string line;
  bool saw_command = false;
  while (std::getline(in, line) && !line.empty() && line[0] == '#')
    saw_command = saw_command || line.rfind("# command: puncture ", 0) == 0;
  EXPECT_TRUE(saw_command) << "no provenance header before '" << line << "'";
  return line;
}

}  // namespace puncture::apps::test
