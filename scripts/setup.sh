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

# The BLAS and LAPACK under UMFPACK (the FEM's direct solves) and CHOLMOD
# (the tensor-mass models' factorisations): Debian's reference BLAS, pinned
# when another one (e.g. OpenBLAS, pulled in by some other package) would be
# selected. The FEM reference's Newton path depends on the BLAS's rounding:
# with the serial OpenBLAS the default reference punctured the muscle at
# 1.509 N instead of 1.469 N and then stalled in the dwell at 30 mm even at
# 1/256 of the load step, so the committed references are reproduced only
# with the BLAS they were made with (every output's machine line names it).
# OpenBLAS would make the tensor-mass factorisations 3.4x faster
# (results/comparison/README.md).
select_reference_blas() {
  local arch dir
  arch="$(dpkg-architecture -qDEB_HOST_MULTIARCH 2>/dev/null || echo x86_64-linux-gnu)"
  dir="/usr/lib/$arch"
  [ -f "$dir/blas/libblas.so.3" ] || return 0
  $SUDO update-alternatives --quiet --set "libblas.so.3-$arch" "$dir/blas/libblas.so.3"
  [ -f "$dir/lapack/liblapack.so.3" ] && $SUDO update-alternatives --quiet --set "liblapack.so.3-$arch" "$dir/lapack/liblapack.so.3"
  return 0
}

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  select_reference_blas
  echo "setup: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

echo "setup: installing ${#missing[@]} missing packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
select_reference_blas
echo "setup: done"
