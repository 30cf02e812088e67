#!/usr/bin/env bash
# results_heldout.sh: the tuned preset (results/tuned_preset: everything but d
# calibrated on the default trajectory at 10 mm/s only, d from the FEM at 1 and
# 10 mm/s) validated without retuning on the cases of
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
  "$build/apps/puncture" --ranks "${RANKS:-2}" \
  --model-note "every parameter but d calibrated on the calibration trajectory (10 mm/s) only, results/tuned_preset/single_speed; d then from the viscoelastic FEM at 1 and 10 mm/s with the rest kept; 3 and 20 mm/s, the 25 mm hold and the other slab never seen"
