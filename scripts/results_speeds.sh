#!/usr/bin/env bash
# Regenerates results/validation_speeds/: the tuned preset validated at 1, 3, 10 and
# 20 mm/s (validation/cases/default_speeds.json; its d, rate laws and shaft friction
# were identified at 1 and 10 mm/s, 3 and 20 mm/s are held out), and speed_law.md /
# speed_law.png: each layer's puncture depth and force against speed, beside the FEM's.
# The FEM references come from out/.fem_cache (scripts/results_validation.sh and
# results_heldout.sh make them; a missing one is computed, a few minutes each).
#   bash scripts/results_speeds.sh
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/results_env.sh"
out=results/validation_speeds
# (set -e does not act inside a command that replace_results_folder tests: the
# validate step returns on failure itself.)
write_speeds() {
  mpirun --oversubscribe -np "${RANKS:-2}" "$build/apps/puncture" validate results/tuned_preset/default_tuned.json \
    --cases validation/cases/default_speeds.json -o "$out" --no-vtk -q \
    --model-note "d, the breakthrough rate exponents n, the cutting viscous fractions b, the release rate exponents m and the shaft friction identified at 1 and 10 mm/s, every other parameter at 10 mm/s only; 3 and 20 mm/s never seen" || return 1
  "$(command -v /usr/bin/python3 || command -v python3)" scripts/speed_law.py results/tuned_preset/default_tuned.json "$out"
}
source scripts/results_folder.sh
replace_results_folder "$out" write_speeds
echo "wrote $out"
