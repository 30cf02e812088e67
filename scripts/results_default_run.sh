#!/usr/bin/env bash
# Regenerates results/default_run/: the default scene through the real-time
# model (and the FEM reference when it has been run into out/default_fem),
# force-depth plot, events table, SH fit-error table, with provenance.
#   bash scripts/results_default_run.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PUNCTURE_BUILD_DIR:-$root/build}"
cd "$root"
[ -x "$build/apps/puncture" ] || bash scripts/build.sh
out="$root/out/default"
"$build/apps/puncture" run scenes/default.json -o "$out" -q
dest="$root/results/default_run"
mkdir -p "$dest"
when="$(date -u +%Y-%m-%dT%H:%M:%SZ)"
machine="$(hostname) ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores)"
rev="$(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
note="bash scripts/results_default_run.sh | $machine | $when | git $rev"
load="$(cut -d' ' -f1-3 /proc/loadavg)"
fem_args=()
if [ -f "$root/out/default_fem/fem_force_depth.csv" ]; then fem_args=(--fem "$root/out/default_fem"); fi
/usr/bin/python3 scripts/plot_force_depth.py "$out" "$dest/force_depth.png" \
  --title "Default scene (Table 2 slab, 18 G needle, 10 mm/s)" --note "$note" "${fem_args[@]}"
cp "$out/summary.json" "$dest/summary.json"
cp "$out/sh_fit_error.csv" "$dest/sh_fit_error.csv"
/usr/bin/python3 - "$out/summary.json" "$dest/README.md" "$note" "$load" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
lines = ["# Default scene: real-time model", "",
         f"Made by `{sys.argv[3].split(' | ')[0]}` on {sys.argv[3].split(' | ')[1]}, {sys.argv[3].split(' | ')[2]} ({sys.argv[3].split(' | ')[3]}).", "",
         "![force-depth](force_depth.png)", "",
         "## Puncture events", "", "| layer | time (s) | depth (mm) | surface force (N) | needle force (N) |", "|---|---|---|---|---|"]
for e in s["puncture_events"]:
    lines.append(f'| {e["layer"]} | {e["time_s"]:.3f} | {e["depth_mm"]:.2f} | {e["surface_force_N"]:.3f} | {e["total_force_N"]:.3f} |')
lines += ["", f'Peak needle force {s["peak_force_N"]:.3f} N at {s["peak_force_depth_mm"]:.2f} mm.',
          f'Tick wall time inside this run, over the {s["tick_timing_us"]["contact_ticks"]} ticks with contact (of '
          f'{s["tick_timing_us"]["ticks"]}): mean {s["tick_timing_us"]["contact_mean"]:.2f} us, p99 '
          f'{s["tick_timing_us"]["contact_p99"]:.2f} us, load average {sys.argv[4]} while it ran '
          '(benchmarks in results/benchmarks/).', "",
          "## SH surface fit error versus degree l", "", "See `sh_fit_error.csv` (top-face error against the exact plane, whole-surface error, condition number).", ""]
tmp = sys.argv[2] + ".tmp"
open(tmp, "w").write("\n".join(lines) + "\n")
import os; os.replace(tmp, sys.argv[2])
PY
echo "results/default_run updated"
