#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer.
#
# Builds the project in its own directory (build-sanitize/, RelWithDebInfo:
# -O2 -g) with -fsanitize=address,undefined -fno-sanitize-recover=undefined
# -fno-omit-frame-pointer (GCC; the libraries from Debian, deal.II, Trilinos,
# OpenMPI, VTK, are not instrumented, only the project's code is), then runs
# every ctest test: any heap error, leak or undefined behaviour in the
# project's code fails the test that hit it.
#
# Suppressions (scripts/sanitizers/, each line commented there):
#   lsan.supp   leaks reported inside OpenMPI, its PMIx/hwloc/libevent
#               components and the dlopen'ed MCA plugins: memory those
#               libraries keep until exit by design (the usual OpenMPI
#               suppressions); nothing of the project's own code.
#   ubsan.supp  empty: no undefined behaviour is suppressed.
# The allocation test (tests/core/test_no_allocation.cpp) counts through
# ASan's allocation hook in this build instead of interposing malloc.
#
# The Python module is left out: an instrumented extension cannot be loaded
# into Debian's uninstrumented python3 (the ASan runtime must come first).
#
# Tests that start MPI run without leak detection (reasons below, at the
# ctest calls); under ASan the reference_fem label takes several times its
# usual ~5 minutes.
#
# Usage: bash scripts/sanitize.sh [--build-only] [extra ctest arguments]
# Env:   PUNCTURE_SANITIZE_BUILD_DIR  build directory (default ./build-sanitize)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PUNCTURE_SANITIZE_BUILD_DIR:-$root/build-sanitize}"
build_only=0
if [[ "${1:-}" == "--build-only" ]]; then build_only=1; shift; fi

bash "$root/scripts/setup.sh"
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_FLAGS="$flags" -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DPUNCTURE_BUILD_BENCHMARKS=OFF -DPUNCTURE_WITH_PYTHON=OFF
# The build runs every test program once to list its tests (gtest discovery):
# no leak check there, it only lists.
ASAN_OPTIONS=detect_leaks=0 cmake --build "$build" -j2
(( build_only )) && exit 0

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
# OpenMPI's memory patcher hooks mmap/munmap, which AddressSanitizer owns;
# keeping its plugins loaded at exit lets the leak report name them.
export OMPI_MCA_memory=^patcher OMPI_MCA_mca_base_component_disable_dlclose=1
# detect_leaks: LeakSanitizer at exit; the ODR check is off because deal.II's
# and Trilinos' shared libraries define the same symbols (not our code).
export ASAN_OPTIONS="detect_leaks=1:detect_odr_violation=0:check_initialization_order=1:strict_init_order=1:abort_on_error=0"
export LSAN_OPTIONS="suppressions=$root/scripts/sanitizers/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$root/scripts/sanitizers/ubsan.supp"
cd "$build"
# Tests that initialise MPI (the FEM: label reference_fem, and the apps tests
# that run the FEM in process) end with a LeakSanitizer report of about
# 117 kB in ~3350 allocations made by modules that were unloaded before the
# check (OpenMPI/PMIx plugins; the report shows "<unknown module>", so no
# suppression can name them). They run with leak detection off; AddressSanitizer
# (heap, stack, use-after-free) and UBSan stay on for them, and every other
# test, which does not start MPI, runs with leak detection on.
# The puncture-app tests (PunctureApp.*) render offscreen: Mesa's GL driver is
# loaded and unloaded by the app, and the leak check at exit reports 240 bytes
# in 3 allocations at addresses it attributes to whatever library now occupies
# them (a different Trilinos library each run), so no suppression can name
# them either; they too run with leak detection off.
mpi_tests='FemReferenceCache|FemReferenceKey.RealtimeOnly|ValidateCommand.Report|SweepCommand|CompareCommand.TableRanking|PunctureApp\.'
status=0
ctest --output-on-failure -j2 --timeout 3000 -LE reference_fem -E "$mpi_tests" "$@" || status=1
no_leaks="${ASAN_OPTIONS/detect_leaks=1/detect_leaks=0}"
ASAN_OPTIONS="$no_leaks" ctest --output-on-failure -j2 --timeout 3000 -R "$mpi_tests" "$@" || status=1
ASAN_OPTIONS="$no_leaks" ctest --output-on-failure -j1 --timeout 3000 -L reference_fem "$@" || status=1
exit $status
