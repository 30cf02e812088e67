// main() of the fem_cache suite: like gtest_main, but MPI (initialised when a
// test runs the FEM) is finalised before static destruction.
#include <gtest/gtest.h>

#include "puncture/validation/fem_reference.hpp"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  const int result = RUN_ALL_TESTS();
  puncture::validation::finalize_mpi();
  return result;
}
