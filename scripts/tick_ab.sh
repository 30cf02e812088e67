#!/usr/bin/env bash
# A/B of the haptic tick's cost and forces between two builds of `puncture`:
# for each scene, runs `puncture run <scene>` with each binary in turn (before,
# after, before, ... RUNS times each, interleaved so that the load of a shared
# machine falls on both alike), and writes a markdown section: the median over
# the runs of the tick statistics that summary.json records (mean and p99 of
# the wall time of tick() over the ticks with contact), each run's values,
# and the largest difference of every force column of realtime_curve.csv
# between the two builds' first runs.
#
#   bash scripts/tick_ab.sh BEFORE_BIN AFTER_BIN [scene,scene,...] [out.md]
#   (scenes default results/tuned_preset/default_tuned.json,scenes/default.json;
#    RUNS default 7; BEFORE_REV / AFTER_REV: the revisions the binaries were
#    built from)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
before="$1" after="$2"
scenes="${3:-results/tuned_preset/default_tuned.json,scenes/default.json}"
out="${4:-/dev/stdout}"
runs="${RUNS:-7}"
cd "$root"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
started="$(date -u '+%Y-%m-%d %H:%M UTC')"
echo "# Haptic tick before and after" > "$work/page.md"
IFS=, read -r -a scene_list <<< "$scenes"
for scene in "${scene_list[@]}"; do
  load_before="$(cut -d' ' -f1-3 /proc/loadavg)"
  rm -rf "$work"/before_* "$work"/after_*
  for ((i = 1; i <= runs; ++i)); do
    for side in before after; do
      bin="$before"; [ "$side" = after ] && bin="$after"
      "$bin" run "$scene" -o "$work/${side}_$i" --no-frames -q
    done
  done
  load_after="$(cut -d' ' -f1-3 /proc/loadavg)"
  "$(command -v /usr/bin/python3 || command -v python3)" - "$work" "$runs" "$scene" "$started" "$load_before" \
    "$load_after" "${BEFORE_REV:-$before}" "${AFTER_REV:-$after}" >> "$work/page.md" <<'PY'
import csv, json, os, socket, statistics, sys
work, runs, scene, started, load_before, load_after, rev_before, rev_after = sys.argv[1:9]
runs = int(runs)


def timing(side, i):
    with open(os.path.join(work, f"{side}_{i}", "summary.json")) as f:
        found = [json.load(f)]
    while found:  # the tick_timing_us object, wherever it sits
        x = found.pop()
        if isinstance(x, dict):
            if "tick_timing_us" in x:
                return x["tick_timing_us"]
            found.extend(x.values())
    raise SystemExit("tick_ab.sh: no tick_timing_us in summary.json")


def curve(side):
    with open(os.path.join(work, f"{side}_1", "realtime_curve.csv")) as f:
        return list(csv.reader(line for line in f if not line.startswith("#")))


def cpu_model():
    with open("/proc/cpuinfo") as f:
        for line in f:
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return "unknown"


t = {side: [timing(side, i) for i in range(1, runs + 1)] for side in ("before", "after")}
a, b = curve("before"), curve("after")
if len(a) != len(b):
    raise SystemExit("tick_ab.sh: the two curves differ in rows")
# The force columns both builds write (a build may add columns); those only one writes are listed.
force_columns = [(k, b[0].index(name)) for k, name in enumerate(a[0]) if name.endswith("_N") and name in b[0]]
only = sorted(set(a[0]) ^ set(b[0]))
worst = {a[0][k]: 0.0 for k, _ in force_columns}
for ra, rb in zip(a[1:], b[1:]):
    for k, j in force_columns:
        worst[a[0][k]] = max(worst[a[0][k]], abs(float(ra[k]) - float(rb[j])))
peak = max(abs(float(r[a[0].index("force_N")])) for r in a[1:])
print(f"\n## `{scene}`\n")
print(f"- Command: `bash scripts/tick_ab.sh BEFORE AFTER` (RUNS={runs}: `puncture run {scene} --no-frames -q` "
      "with each binary in turn, interleaved)")
busy = max(float(load_before.split()[0]), float(load_after.split()[0])) > 1.0
print(f"- Machine: {cpu_model()}, {os.cpu_count()} cores, host `{socket.gethostname()}`; "
      + ("shared with other work during the measurement" if busy else "otherwise idle")
      + f" (load average {load_before} before, {load_after} after)")
print(f"- Date: {started}")
print(f"- Before: {rev_before}; after: {rev_after}")
print("- Times: wall time of tick() measured inside each run (summary.json `tick_timing_us`), over the "
      f"{t['after'][0]['contact_ticks']} ticks with contact; median over the runs, then every run\n")
print("| build | contact mean us | contact p99 us | runs: mean / p99 us |")
print("|---|---|---|---|")
for side in ("before", "after"):
    mean = statistics.median(x["contact_mean"] for x in t[side])
    p99 = statistics.median(x["contact_p99"] for x in t[side])
    each = ", ".join(f"{x['contact_mean']:.2f} / {x['contact_p99']:.1f}" for x in t[side])
    print(f"| {side} | {mean:.2f} | {p99:.2f} | {each} |")
print(f"\nForces: largest difference between the two builds over the {len(a) - 1} ticks of realtime_curve.csv "
      f"(peak needle force {peak:.4g} N):\n")
print("| column | max abs difference N |")
print("|---|---|")
for name, d in worst.items():
    print(f"| {name} | {d:.3g} |")
if only:
    print(f"\nColumns of one build only: {', '.join(only)}")
PY
done
cat "$work/page.md" > "$out"
