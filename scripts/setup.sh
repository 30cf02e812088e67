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
  libopenblas0-serial               # optimised BLAS/LAPACK under CHOLMOD and UMFPACK (see below)
  libcgal-dev                       # meshing
  libvtk9-dev                       # VTK output
  libnlopt-cxx-dev libnlopt-dev libgsl-dev   # calibration
  openmpi-bin libopenmpi-dev        # MPI runs of the FEM
  python3 python3-matplotlib python3-numpy   # plots in results/
  xvfb                              # offscreen rendering in CI
  clang libclang-rt-14-dev          # libFuzzer target of the scene reader (tests/fuzz/)
)

# The BLAS and LAPACK that CHOLMOD (the tensor-mass models' factorisations)
# and UMFPACK (the FEM's direct solves) call: OpenBLAS, single-threaded (the
# comparison runs two models at a time on two cores), instead of Debian's
# reference BLAS, which is about 3.4x slower on these factorisations
# (results/comparison/README.md). Chosen explicitly, so that every machine
# computes with the same library and the same rounding.
select_openblas() {
  local arch dir
  arch="$(dpkg-architecture -qDEB_HOST_MULTIARCH 2>/dev/null || echo x86_64-linux-gnu)"
  dir="/usr/lib/$arch/openblas-serial"
  [ -f "$dir/libblas.so.3" ] || return 0
  $SUDO update-alternatives --quiet --set "libblas.so.3-$arch" "$dir/libblas.so.3"
  $SUDO update-alternatives --quiet --set "liblapack.so.3-$arch" "$dir/liblapack.so.3"
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
  select_openblas
  echo "setup: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

echo "setup: installing ${#missing[@]} missing packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
select_openblas
echo "setup: done"
