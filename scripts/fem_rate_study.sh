#!/usr/bin/env bash
# fem_rate_study.sh: the FEM reference of a scene at several insertion speeds
# (default 1, 3 and 10 mm/s; withdrawal at the same speed), beside the
# measured speed trends: results/fem_rate/ (README.md with the table and the
# trends, rate.json, fem_rate_force_depth.png). About 2 min per speed on
# 2 cores (scenes/default.json).
#   bash scripts/fem_rate_study.sh [SCENE] [OUT_DIR]     (SPEEDS="1 3 10" RANKS=2)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PUNCTURE_BUILD_DIR:-$root/build}"
scene="${1:-scenes/default.json}"
out="${2:-results/fem_rate}"
speeds="${SPEEDS:-1 3 10}"
cd "$root"
[ -x "$build/apps/puncture" ] || bash scripts/build.sh
py="$(command -v /usr/bin/python3 || command -v python3)"
export OMPI_ALLOW_RUN_AS_ROOT="${OMPI_ALLOW_RUN_AS_ROOT:-1}" OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="${OMPI_ALLOW_RUN_AS_ROOT_CONFIRM:-1}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
args=()
for v in $speeds; do
  "$py" - "$scene" "$work/speed_$v.json" "$v" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
v = float(sys.argv[3])
s["name"] = f"{s['name']}_{sys.argv[3]}mm_per_s"
s["insertion"]["speed_mm_per_s"] = v
s["insertion"]["withdrawal_speed_mm_per_s"] = v
json.dump(s, open(sys.argv[2], "w"), indent=2)
PY
  echo "fem_rate_study: $scene at $v mm/s"
  mpirun --oversubscribe -np "${RANKS:-2}" "$build/apps/puncture" fem "$work/speed_$v.json" -o "$work/fem_$v" --no-vtu -q
  args+=("$v=$work/fem_$v")
done
"$py" scripts/fem_rate_study.py "$out" "$scene" "bash scripts/fem_rate_study.sh $scene $out (SPEEDS=\"$speeds\")" "${args[@]}"
