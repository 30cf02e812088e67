#!/usr/bin/env bash
# Wall time of the FEM reference of one scene with several builds of `puncture`
# on this machine: runs `mpirun -np 2 BIN fem SCENE --no-vtu` for each build in
# turn, RUNS rounds (interleaved, so that the load of a shared machine falls on
# every build alike), keeps the run directories under out/fem_timing_ab/, and
# writes the page of scripts/fem_axisymmetric_timing.py: one row per build, the
# median wall time and each run's, with the load average before and after and
# each binary's `--version` in its notes.
#
#   bash scripts/fem_timing_ab.sh OUT_MD LABEL=BIN [LABEL=BIN ...]
#   (SCENE default scenes/default.json; RUNS default 3)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/results_env.sh"
[ $# -ge 2 ] || { echo "usage: bash scripts/fem_timing_ab.sh OUT_MD LABEL=BIN [LABEL=BIN ...]" >&2; exit 2; }
out_md="$1"; shift
scene="${SCENE:-scenes/default.json}"
runs="${RUNS:-3}"
work="out/fem_timing_ab"
rm -rf "$work"
mkdir -p "$work"
for pair in "$@"; do
  bin="${pair#*=}"
  [ -x "$bin" ] || { echo "fem_timing_ab: $bin is not an executable (from '$pair')" >&2; exit 2; }
done
load_before="$(cut -d' ' -f1-3 /proc/loadavg)"
args=()
for ((i = 1; i <= runs; ++i)); do
  for pair in "$@"; do
    label="${pair%%=*}" bin="${pair#*=}"
    echo "fem_timing_ab: round $i of $runs, $label" >&2
    mpirun -np 2 "$bin" fem "$scene" -o "$work/${label}_$i" --no-vtu -q
    args+=("$label=$work/${label}_$i")
  done
done
load_after="$(cut -d' ' -f1-3 /proc/loadavg)"
notes=(--note "made by \`RUNS=$runs SCENE=$scene bash scripts/fem_timing_ab.sh $out_md $*\`" --note "$(basename "$scene") with each build, $runs rounds interleaved (mpirun -np 2, --no-vtu); load average before $load_before, after $load_after")
for pair in "$@"; do
  label="${pair%%=*}" bin="${pair#*=}"
  notes+=(--note "$label: \`$("$bin" --version | head -1)\`")
done
/usr/bin/python3 scripts/fem_axisymmetric_timing.py "$out_md" "${notes[@]}" "${args[@]}"
