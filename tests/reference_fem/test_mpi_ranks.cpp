// Run under mpirun -np 2 (ctest reference_fem.one_rank_versus_two_ranks):
// the needle force curve on 2 ranks equals the one on 1 rank (each rank also
// solves the whole problem alone on MPI_COMM_SELF) to solver tolerance.
#include <deal.II/base/mpi.h>
#include <gtest/gtest.h>

#include <cmath>

#include "fem_test_scenes.hpp"

using namespace puncture;
using namespace puncture::fem;
using namespace puncture::fem::testing;

TEST(MpiRanks, TwoRanksGiveTheSameForceCurveAsOne) {
  const int n_ranks = dealii::Utilities::MPI::n_mpi_processes(MPI_COMM_WORLD);
  ASSERT_EQ(n_ranks, 2) << "launch with mpirun -np 2";
  Scene s = small_three_layer_scene();
  FemRunOptions o;
  o.mesh = coarse_mesh();
  o.verbose = false;
  o.write_files = false;
  o.stop_depth_m = 2.0e-3;
  const FemRunSummary parallel = run_needle_insertion(s, o, MPI_COMM_WORLD);
  const FemRunSummary serial = run_needle_insertion(s, o, MPI_COMM_SELF);
  EXPECT_EQ(parallel.n_ranks, 2);
  EXPECT_EQ(serial.n_ranks, 1);
  EXPECT_EQ(parallel.n_dofs, serial.n_dofs);
  ASSERT_EQ(parallel.force_N.size(), serial.force_N.size());
  ASSERT_FALSE(parallel.punctures.empty());
  ASSERT_EQ(parallel.punctures.size(), serial.punctures.size());
  for (std::size_t i = 0; i < serial.force_N.size(); ++i) {
    EXPECT_DOUBLE_EQ(parallel.depth_m[i], serial.depth_m[i]);
    EXPECT_NEAR(parallel.force_N[i], serial.force_N[i], 1e-6 * std::abs(serial.force_N[i]) + 1e-12)
        << "row " << i;
  }
  EXPECT_GT(serial.peak_force_N, 0.0);
}
