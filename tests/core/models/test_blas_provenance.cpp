// The machine line of every output names the BLAS the process computes with
// (io::blas_library): the comparison models' CHOLMOD loads one, and the last
// digits and the speed of its factorisations depend on which.
#include <gtest/gtest.h>

#include <string>

#include "puncture/io/provenance.hpp"

using namespace puncture;

TEST(BlasProvenance, TheBlasUnderCholmodIsNamedInTheMachineSummary) {
  const std::string blas = io::blas_library();
  ASSERT_FALSE(blas.empty()) << "this test program links CHOLMOD, which loads a BLAS";
  EXPECT_EQ(blas.find('/'), std::string::npos) << "a library's folder name, not a path: " << blas;
  const std::string machine = io::machine_summary();
  EXPECT_NE(machine.find(" cores, " + blas + ")"), std::string::npos) << machine;
}
