#!/usr/bin/env bash
# results_slab_rule.sh: the slab rule of the tuned model (how its real-time
# parameters follow each layer's thickness), fitted on a family of calibration
# slabs, for slabs the model is never calibrated on (scripts/results_heldout.sh
# gives results/slab_rule/slab_rule.json to puncture validate --slab-rule: the
# held-out slab of validation/cases/default_heldout.json takes its parameters
# from it).
#   results/slab_rule/<slab>/   puncture calibrate of the tuned preset on that
#                               slab (its FEM reference at 10 mm/s): the force
#                               meshes from the FEM's surface (--surface-fit),
#                               then the critical forces, cutting and releases;
#                               the shaft friction and the rate parameters (d, n,
#                               b, m) are the material's and are kept
#   results/slab_rule/slab_rule.{json,md}  puncture slab-rule on the six presets: each
#                               parameter that moved, where three calibrations or
#                               more identified it, as a power law in its layer's
#                               thickness or the depth of its top
# The family brackets the held-out slab (skin 1.2, fat 5, muscle 30 mm): skin
# 0.8-1.6 mm, fat 4.5-9 mm, muscle 28-39 mm; the muscle's top lies 6.1-10.4 mm
# deep (the fourth slab, added to test the rule's choice between a layer's
# thickness and its depth out of sample, puts it 8.8 mm deep over 32 mm; the
# fifth and sixth, added when the rule began to take only identified values,
# give the fat and the muscle's force mesh more slabs). One FEM run per slab (cached in
# out/.fem_cache, 1.5-3 min each on 2 cores), then 1.5-3 min of calibration
# each. Run after scripts/results_validation.sh (it reads its tuned preset).
#   bash scripts/results_slab_rule.sh        (RANKS=2)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/results_env.sh"
out=results/slab_rule
source scripts/results_folder.sh
mpi=(mpirun --oversubscribe -np "${RANKS:-2}")
# The first member is the default slab: the rule's reference thicknesses.
family=("default:0.8,8.4,39" "thick_skin_thin_fat:1.6,4.5,36" "thin_muscle:1.0,6.5,28"
        "deep_muscle:1.3,7.5,32" "mid_fat:1.0,5.5,36" "thick_fat:1.4,9,33")
# (set -e does not act inside a command that replace_results_folder tests: each
# step returns on failure itself.)
make_slab_rule() {
  local presets=() member name thickness
  for member in "${family[@]}"; do
    name="${member%%:*}" thickness="${member#*:}"
    echo "[slab_rule] calibrating on slab $name ($thickness mm)"
    "${mpi[@]}" "$build/apps/puncture" calibrate results/tuned_preset/default_tuned.json -o "$out/$name" \
      --name "slab_$name" --layer-thickness "$thickness" --surface-fit --keep friction \
      --integrator implicit --force-weight 4 --depth-weight 1 -q || return 1
    presets+=("$out/$name/slab_$name.json")
  done
  "$build/apps/puncture" slab-rule "${presets[@]}" -o "$out" || return 1
}
replace_results_folder "$out" make_slab_rule
echo "wrote $out"
