#!/usr/bin/env bash
# results_heldout.sh: the tuned preset (results/tuned_preset: everything but d
# calibrated on the default trajectory at 10 mm/s only, d from the FEM at 1 and
# 10 mm/s) validated without retuning on the cases of
# validation/cases/default_heldout.json by `puncture validate --cases`:
# results/validation_heldout/ (heldout_summary.json and .md, one report per
# case with its scene.json; no VTK). The other slab takes its parameters from
# the model's slab rule (results/slab_rule, scripts/results_slab_rule.sh: run it
# first). One FEM run per case (cached in
# out/.fem_cache), about 2 min each on 2 cores when not cached.
#   bash scripts/results_heldout.sh          (RANKS=2)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/results_env.sh"
out=results/validation_heldout
source scripts/results_folder.sh
replace_results_folder "$out" mpirun --oversubscribe -np "${RANKS:-2}" "$build/apps/puncture" validate results/tuned_preset/default_tuned.json \
  --cases validation/cases/default_heldout.json --slab-rule results/slab_rule/slab_rule.json -o "$out" --no-vtk -q \
  --why-misses validation/cases/default_tuned_why_misses.json \
  --model-note "every parameter but d, n, b, m and the shaft friction calibrated on the calibration trajectory (10 mm/s) only, results/tuned_preset/single_speed; d, the breakthrough rate exponents n, the cutting viscous fractions b, the release rate exponents m and the shaft friction (f_d, presliding; its pressure relaxes with each layer's Prony series, not fitted) then from the viscoelastic FEM at 1 and 10 mm/s with the rest kept; 3 and 20 mm/s, the 25 mm hold and the other slab never seen; the other slab's parameters from the slab rule (results/slab_rule: the model calibrated again, friction and rate parameters kept, on a family of six slabs (the default and five others), skin 0.8-1.6 mm, fat 4.5-9 mm, muscle 28-39 mm; each slab's value only where its calibration identified it)"
echo "wrote $out"
