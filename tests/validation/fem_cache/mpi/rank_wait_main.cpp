// Run under `mpirun -np 2` (ctest fem_cache.mpi_ranks_share_the_cores): what
// fem_reference.hpp promises the ranks of a command such as
// `mpirun -np 2 puncture compare`, whose FEM references all come from the cache.
// - After ensure_mpi(), rank 0 may run on every online core, although mpirun
//   bound it to one (it does the rest of the command, with two threads where
//   it can).
// - A rank waiting in finalize_mpi() for rank 0 sleeps: while rank 0 works for
//   2 s, the waiting rank uses less than 0.1 s of CPU (MPI_Finalize's own wait
//   polled: about 20 % of a core).
// Exit status 0 when both hold on every rank; each failure is printed.
#include <sched.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <thread>

#include <mpi.h>

#include "puncture/validation/fem_reference.hpp"

namespace {

double process_cpu_s() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

int main() {
  puncture::validation::ensure_mpi();
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  int failures = 0;
  if (size != 2) {
    std::fprintf(stderr, "rank %d: run me with mpirun -np 2 (got %d ranks)\n", rank, size);
    ++failures;
  }
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  if (rank == 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    sched_getaffinity(0, sizeof set, &set);
    if (online >= 2 && CPU_COUNT(&set) < 2) {
      std::fprintf(stderr, "rank 0 may run on %d of %ld online cores after ensure_mpi()\n", CPU_COUNT(&set), online);
      ++failures;
    }
    std::this_thread::sleep_for(std::chrono::seconds(2));  // the rest of the command
  }
  const auto wall_start = std::chrono::steady_clock::now();
  const double cpu_start = process_cpu_s();
  puncture::validation::finalize_mpi();
  const double cpu_s = process_cpu_s() - cpu_start;
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  if (rank != 0) {
    if (wall_s < 1.5) {
      std::fprintf(stderr, "rank %d left finalize_mpi() after %.2f s, before rank 0 got there\n", rank, wall_s);
      ++failures;
    }
    if (cpu_s > 0.1) {
      std::fprintf(stderr, "rank %d used %.3f s of CPU in %.2f s of waiting for rank 0\n", rank, cpu_s, wall_s);
      ++failures;
    }
  }
  std::printf("rank %d: %s (waited %.2f s, %.3f s CPU)\n", rank, failures ? "FAILED" : "ok", wall_s, cpu_s);
  return failures ? 1 : 0;
}
