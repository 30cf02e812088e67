#!/usr/bin/env bash
# Installs every Debian package the project needs. Idempotent: packages that
# are already installed are skipped, and `apt-get update` runs at most once per
# invocation (only if something is missing). Works as root on Debian 12; uses
# sudo otherwise.
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev                     # core: linear algebra
  nlohmann-json3-dev libcli11-dev   # scenes, command line
  libgtest-dev libgmock-dev googletest libbenchmark-dev  # tests, benchmarks
  libdeal.ii-dev                    # reference_fem (brings Trilinos, p4est, MPI)
  libsundials-dev                   # integrators
  libsuitesparse-dev                # CHOLMOD: the volumetric comparison models' sparse Cholesky
  libcgal-dev                       # meshing
  libvtk9-dev                       # VTK output
  libnlopt-cxx-dev libnlopt-dev libgsl-dev   # calibration
  openmpi-bin libopenmpi-dev        # MPI runs of the FEM
  python3 python3-matplotlib python3-numpy   # plots in results/
  pybind11-dev python3-dev python3-pytest    # the Python module (apps/python) and its tests
  xvfb                              # offscreen rendering in CI
  clang libclang-rt-14-dev          # libFuzzer target of the scene reader (tests/fuzz/)
)

# The BLAS is left as the machine selects it: the FEM reference's committed
# scenes give the same curves under Debian's reference BLAS and the serial
# OpenBLAS to 1e-10 of the peak force (results/fem_reproducibility/), and
# every output's machine line names the BLAS it ran with. Under the serial
# OpenBLAS (libopenblas0-serial: not safe to call from two threads of one
# process) `puncture compare` runs its models one at a time and says so; the
# threaded libopenblas0-pthread, or the reference BLAS, lets them run two at a
# time (results/comparison/README.md).

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

echo "setup: installing ${#missing[@]} missing packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "setup: done"
