#!/usr/bin/env bash
# results/soak/: 10^7 haptic ticks over random needle trajectories with every
# effect on (tests/soak/soak_driver.hpp): no NaN, mesh energy bounded by the
# work done on it, no heap allocation inside tick(). Writes
# results/soak/soak.md (table with provenance) and soak.json.
#   bash scripts/results_soak.sh [TICKS] [SEED]     (defaults 10000000, 1)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PUNCTURE_BUILD_DIR:-$root/build}"
ticks="${1:-10000000}"
seed="${2:-1}"
cd "$root"
[[ -x "$build/tests/puncture_soak" ]] || bash scripts/build.sh
"$build/tests/puncture_soak" --ticks "$ticks" --seed "$seed" --out results/soak
