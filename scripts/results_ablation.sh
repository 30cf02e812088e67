#!/usr/bin/env bash
# results_ablation.sh: the seed paper's model, then each mechanism of the
# tuned real-time model added one at a time, judged on the held-out cases
# (validation/cases/default_heldout.json) with the tick cost of each:
# results/ablation/ (README.md, ablation.json). Run after
# scripts/results_validation.sh and scripts/results_heldout.sh (the FEM of
# every case is then cached) and scripts/results_slab_rule.sh (the tuned
# preset's slab rule: a row of its own); about 1 min per row and case.
#   bash scripts/results_ablation.sh          (RANKS=2)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PUNCTURE_BUILD_DIR:-$root/build}"
cd "$root"
[ -x "$build/apps/puncture" ] || bash scripts/build.sh
"$(command -v /usr/bin/python3 || command -v python3)" scripts/ablation.py results/tuned_preset/default_tuned.json \
  scenes/paper_table2.json validation/cases/default_heldout.json results/ablation "$build/apps/puncture" \
  --ranks "${RANKS:-2}" --slab-rule results/slab_rule/slab_rule.json
