#!/usr/bin/env bash
# liver_fem_identification.sh: the liver scene's FEM beside the measured
# Okamura 2004 curve, and its capsule strength, parenchyma modulus and
# friction identified against the curve by Nelder-Mead over FEM runs:
# results/liver_fem/ (README.md, identification.json, evaluations.csv,
# liver_fem_vs_okamura.png, liver_identified.json). About 25 min on 2 cores.
#   bash scripts/liver_fem_identification.sh       (EVALUATIONS=24 RANKS=2)
# FROM_EVALUATIONS=results/liver_fem/evaluations.csv rewrites the page from an
# earlier search's best run (two FEM runs instead of the search).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PUNCTURE_BUILD_DIR:-$root/build}"
shared="${PUNCTURE_SHARED_DATA_DIR:-../shared/data}"  # relative to the repository
cd "$root"
[ -x "$build/apps/puncture" ] || bash scripts/build.sh
"$(command -v /usr/bin/python3 || command -v python3)" scripts/liver_fem_identification.py scenes/liver_okamura.json \
  "$shared/okamura2004_liver_depth_force.csv" results/liver_fem "$build/apps/puncture" \
  --evaluations "${EVALUATIONS:-24}" --ranks "${RANKS:-2}" \
  ${FROM_EVALUATIONS:+--from-evaluations "$FROM_EVALUATIONS"}
