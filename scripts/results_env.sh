# results_env.sh (sourced by the results scripts): sets $root (the repository,
# made the working directory) and $build (PUNCTURE_BUILD_DIR, else build/; built
# by scripts/build.sh when its puncture binary is missing), and lets OpenMPI run
# as root (the CI machine's user).
#   source "$(dirname "${BASH_SOURCE[0]}")/results_env.sh"
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PUNCTURE_BUILD_DIR:-$root/build}"
cd "$root"
[ -x "$build/apps/puncture" ] || bash scripts/build.sh
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
