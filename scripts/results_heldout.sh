#!/usr/bin/env bash
# results_heldout.sh: the tuned preset (results/tuned_preset, calibrated on the
# default trajectory only) validated without retuning on the cases of
# validation/cases/default_heldout.json: results/validation_heldout/
# (heldout_summary.json and .md, one folder per case). One FEM run per case
# (cached in out/.fem_cache), about 2 min each on 2 cores.
#   bash scripts/results_heldout.sh          (RANKS=2)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PUNCTURE_BUILD_DIR:-$root/build}"
cd "$root"
[ -x "$build/apps/puncture" ] || bash scripts/build.sh
"$(command -v /usr/bin/python3 || command -v python3)" scripts/heldout_validation.py \
  results/tuned_preset/default_tuned.json validation/cases/default_heldout.json results/validation_heldout \
  "$build/apps/puncture" --ranks "${RANKS:-2}"
