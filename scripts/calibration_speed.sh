#!/usr/bin/env bash
# Benchmark: how long `puncture calibrate` takes, and what each gain came from.
#
#   bash scripts/calibration_speed.sh [output dir]     (default results/calibration_speed)
#
# Cases: the default slab (scenes/default_force_law.json against its cached
# FEM reference, the command of scripts/results_validation.sh), the liver
# scene against the measured Okamura 2004 curve (../shared/data) and the
# skin-on-muscle phantom against the shared rig-like raw recording (issue 49:
# no hand-entered depth). CASES="rig" (any of default, liver, rig) remakes
# only those cases' rows: every row is kept in rows.tsv beside the README,
# with the machine, date, revision and load average it was made at, and the
# README is written from all of them. Rows: the
# derivative-free Nelder-Mead with whole model runs on one thread (the
# calibration as it was, with this build's cheaper model runs), with runs that
# turn past each stage's depths, then Levenberg-Marquardt on one thread and
# on every core. LM rows are the median of REPEATS runs (default 5), NM rows
# one run each (4-10 minutes apiece). PUNCTURE_BEFORE_BIN=<puncture binary of
# an older revision> adds its default-slab run and its two steps of the tuned
# preset as "before" rows, with the revision given by PUNCTURE_BEFORE_REV (it
# must have the same FEM cache key: the references are not timed). Writes README.md (the table, the
# command, machine, date) and the runs' calibration summaries.
# The machine should be otherwise idle: these are wall-clock times.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PUNCTURE_BUILD_DIR:-$root/build}"
out="${1:-$root/results/calibration_speed}"
repeats="${REPEATS:-5}"
shared="${PUNCTURE_SHARED_DATA_DIR:-$root/../shared/data}"
cd "$root"
[ -x "$build/apps/puncture" ] || bash scripts/build.sh
export OMPI_ALLOW_RUN_AS_ROOT="${OMPI_ALLOW_RUN_AS_ROOT:-1}" OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="${OMPI_ALLOW_RUN_AS_ROOT_CONFIRM:-1}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

default_args=(scenes/default_force_law.json --integrator implicit --force-weight 4 --depth-weight 1)
liver_args=(scenes/liver_okamura.json --reference "$shared/okamura2004_liver_depth_force.csv"
            --reference-depth-offset 9.5 --puncture-depths 9.65,9.66)
rig_args=(scenes/skin_on_muscle_phantom.json --reference "$shared/rig_like_recording.csv"
          --recording-format validation/cases/rig_like_recording_format.json)
# The tuned preset's two steps (scripts/results_validation.sh), timed together: the force meshes
# from the FEM's surface and everything but d at 10 mm/s, then d and the rate laws at 1 and 10 mm/s
# from the first step's preset (its FEM references cached).
preset_single_args=(scenes/default_force_law.json --integrator implicit --force-weight 4 --depth-weight 1 --surface-fit)
preset_two_speed_args=(--integrator implicit --force-weight 4 --depth-weight 1 --fem-speeds 1,10
                       --keep K,breakthrough,cutting,stiffening)
cases=" ${CASES:-default liver rig preset} "
# The FEM reference of the default slab, computed once if not cached (not timed).
if [[ "$cases" == *" default "* ]]; then
  "$build/apps/puncture" calibrate "${default_args[@]}" -o "$work/warmup" -q >/dev/null
fi

if [[ "$cases" == *" preset "* ]]; then
  "$build/apps/puncture" calibrate "${preset_single_args[@]}" -o "$work/warmup_preset" --name warm -q >/dev/null
  "$build/apps/puncture" calibrate "$work/warmup_preset/warm.json" "${preset_two_speed_args[@]}" \
    -o "$work/warmup_preset_2" -q >/dev/null
fi

rows="$work/rows.tsv"
: > "$rows"
count=0
# run <case> <label> <gain> <n> <binary> <args...>: n runs, records the median wall time, runs and objective.
run() {
  local case="$1" label="$2" gain="$3" n="$4" bin="$5"
  shift 5
  [[ "$cases" == *" $case "* ]] || return 0
  local load
  load=$(cut -d' ' -f1 /proc/loadavg)
  local times=() i=0 summary=""
  for ((i = 1; i <= n; ++i)); do
    count=$((count + 1))
    local dir="$work/run_$count"
    echo "[calibration_speed] $case / $label: run $i of $n" >&2
    local t0 t1
    t0=$(date +%s.%N)
    if [[ "$bin" == preset:* ]]; then  # both steps of the tuned preset, the second from the first's preset
      "${bin#preset:}" calibrate "${preset_single_args[@]}" -o "$dir.single" --name single -q >/dev/null \
        2>"$dir.err" || { cat "$dir.err" >&2; exit 1; }
      "${bin#preset:}" calibrate "$dir.single/single.json" "${preset_two_speed_args[@]}" -o "$dir" --name run \
        -q >/dev/null 2>"$dir.err" || { cat "$dir.err" >&2; exit 1; }
    else
      "$bin" calibrate "$@" -o "$dir" --name run -q >/dev/null 2>"$dir.err" || { cat "$dir.err" >&2; exit 1; }
    fi
    t1=$(date +%s.%N)
    times+=("$(awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.3f", b - a}')")
    summary="$dir/calibration_summary.md"
  done
  local median
  median=$(printf '%s\n' "${times[@]}" | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}')
  local all
  all=$(printf '%s\n' "${times[@]}" | awk '{printf "%s%.1f", (NR > 1 ? ", " : ""), $1}')
  local runs objective
  runs=$(grep -o '[0-9]* model runs in' "$summary" | head -1 | awk '{print $1}')
  objective=$(grep -o 'Objective [0-9.e+-]* -> [0-9.e+-]*' "$summary" | head -1 | awk '{print $4}')
  local exact
  exact=$(python3 -c "import json,sys; print('%.6f' % json.load(open(sys.argv[1]))['objective_after'])" "$(dirname "$summary")/run.provenance.json")
  printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$case" "$label" "$gain" "$median" "$all" "$runs" "$exact" "$n" \
    "$load-$(cut -d' ' -f1 /proc/loadavg)" "$(date -u +%Y-%m-%dT%H:%M:%SZ)" >> "$rows"
  mkdir -p "$out/summaries"
  cp "$summary" "$out/summaries/${case}_$(echo "$label" | tr -c 'A-Za-z0-9' '_' | sed 's/_*$//').md"
}

mkdir -p "$out"
if [ -n "${PUNCTURE_BEFORE_BIN:-}" ]; then
  run default "before (git ${PUNCTURE_BEFORE_REV:-?}): Nelder-Mead, whole runs" "-" 1 "$PUNCTURE_BEFORE_BIN" \
    "${default_args[@]}" --method nelder_mead
fi
run default "Nelder-Mead, whole runs, 1 thread" "model runs without stored ticks, timing or per-tick positions" 1 \
  "$build/apps/puncture" "${default_args[@]}" --method nelder_mead --stage-turn-margin 0 --threads 1
run default "Nelder-Mead, stage runs turn 2 mm past their depths, 1 thread" "shorter per-layer stage runs" 1 \
  "$build/apps/puncture" "${default_args[@]}" --method nelder_mead --threads 1
run default "Levenberg-Marquardt, 1 thread" "least squares on the residual vector: fewer model runs" "$repeats" \
  "$build/apps/puncture" "${default_args[@]}" --threads 1
run default "Levenberg-Marquardt, 2 threads (default)" "Jacobian columns and trial steps on both cores" "$repeats" \
  "$build/apps/puncture" "${default_args[@]}"
run liver "Nelder-Mead, whole runs, 1 thread" "-" 1 \
  "$build/apps/puncture" "${liver_args[@]}" --method nelder_mead --stage-turn-margin 0 --threads 1
run liver "Levenberg-Marquardt, 2 threads (default)" "all of the above" "$repeats" \
  "$build/apps/puncture" "${liver_args[@]}"
run rig "Levenberg-Marquardt, 2 threads (default)" "-" "$repeats" \
  "$build/apps/puncture" "${rig_args[@]}"
if [ -n "${PUNCTURE_BEFORE_BIN:-}" ]; then
  run preset "before (git ${PUNCTURE_BEFORE_REV:-?}): both steps, Levenberg-Marquardt, 2 threads" \
    "cheaper model runs (see the text above the table)" "$repeats" "preset:$PUNCTURE_BEFORE_BIN"
fi
run preset "both steps, Levenberg-Marquardt, 2 threads" \
  "a stiffening force mesh's state kept on the lattice's cells: no per-node work in a tick (the nodes and ring means expanded when asked), each spring's tangent kept from the residual's pass" \
  "$repeats" "preset:$build/apps/puncture"

python3 - "$rows" "$out" <<'EOF'
import subprocess, sys, platform, os
new_rows = [l.rstrip('\n').split('\t') for l in open(sys.argv[1]) if l.strip()]
out = sys.argv[2]
git = subprocess.run(['git', 'rev-parse', '--short', 'HEAD'], capture_output=True, text=True).stdout.strip()
dirty = subprocess.run(['git', 'status', '--porcelain', '--untracked-files=no'], capture_output=True, text=True).stdout.strip()
cpu = next((l.split(':', 1)[1].strip() for l in open('/proc/cpuinfo') if l.startswith('model name')), platform.processor())
machine = f"{platform.node()} ({cpu}, {os.cpu_count()} cores)"
# rows.tsv: case, label, gain, median, runs, model runs, objective, n, load before-after, date, machine, git
store = os.path.join(out, 'rows.tsv')
kept = [l.rstrip('\n').split('\t') for l in open(store) if l.strip()] if os.path.exists(store) else []
remade = {r[0] for r in new_rows}
rows = [r for r in kept if r[0] not in remade] + [r + [machine, f"{git}{'-dirty' if dirty else ''}"] for r in new_rows]
with open(store + '.tmp', 'w') as f:
    f.write(''.join('\t'.join(r) + '\n' for r in rows))
os.replace(store + '.tmp', store)
lines = ["# Calibration speed", "",
         "Made by `bash scripts/calibration_speed.sh` (`CASES=...` remakes some cases; every row is kept in rows.tsv). "
         "Wall time of the whole `puncture calibrate` process (reference already cached; report and plots included); "
         "each table says the machine, date and revision of its runs and the load average (1 min) before the first "
         "and after the last run of each row: a load above the core count means the machine was shared and the times "
         "are longer than on an idle one. Levenberg-Marquardt rows: the median of the runs listed; Nelder-Mead rows: "
         "one run each. The objective is the one the calibration minimises (calibration_summary.md, sum of weight x "
         "value^2 over every term); on one thread Levenberg-Marquardt tries one step per iteration instead of two, so "
         "its path and optimum differ. Each configuration's last calibration summary is in summaries/.", ""]
titles = (("default", "Default slab against its FEM reference (scenes/default_force_law.json, 3 layers, 15 tuned parameters)"),
          ("liver", "Liver against the measured Okamura 2004 curve (scenes/liver_okamura.json, 2 layers, 11 tuned parameters)"),
          ("rig", "Skin-on-muscle phantom against the shared rig-like raw recording (scenes/skin_on_muscle_phantom.json, "
                  "../shared/data/rig_like_recording.csv read raw, its puncture detected; 2 layers, 11 tuned parameters)"),
          ("preset", "The tuned preset of the default slab, both steps of scripts/results_validation.sh together "
                     "(--surface-fit at 10 mm/s, then d, the rate laws and the friction at 1 and 10 mm/s from the first "
                     "step's preset; its FEM references cached). Model runs and objective: the second step's"))
notes = {"preset": "Before: as committed in results/tuned_preset at git 038bbaa (2026-12-04, on the FEM reference of "
                   "that time), the two steps took 92.3 s (650 model runs) and 288 s (770 model runs), objective 0.9797 "
                   "after the second step. Per model run the two steps now cost about 6 times less: the tuned preset's "
                   "haptic tick (its stiffening force meshes stepped on the lattice's cells, "
                   "results/benchmarks/tick_before_after.md) is what the model runs spend their time on. The rows below: "
                   "the binary of the revision before the last gain and this revision's, one after the other on the "
                   "same machine, with the same model runs and the same objective (the tick's forces are the same "
                   "bit for bit). Target (issue 52): both steps in at most 60 s with an objective no worse than "
                   "committed (0.300328, results/tuned_preset)."}
for case, title in titles:
    sel = [r for r in rows if r[0] == case]
    if not sel:
        continue
    made = sorted({f"{r[10]}, {r[9][:10]}, git {r[11]}" for r in sel})
    loads = ', '.join(r[8] if r[8] != '?' else 'not recorded' for r in sel)
    lines += [f"## {title}", ""] + ([notes[case], ""] if case in notes else []) + [
              f"Made on {'; '.join(made)}; load average before-after each row: {loads}.", "",
              "| configuration | gain from | wall time (s, median) | runs (s) | model runs | objective after |",
              "|---|---|---|---|---|---|"]
    for r in sel:
        lines.append(f"| {r[1]} | {r[2]} | {float(r[3]):.1f} | {r[4]} | {r[5]} | {r[6]} |")
    lines.append("")
with open(os.path.join(out, 'README.md.tmp'), 'w') as f:
    f.write('\n'.join(lines))
os.replace(os.path.join(out, 'README.md.tmp'), os.path.join(out, 'README.md'))
EOF
echo "[calibration_speed] $out/README.md"
