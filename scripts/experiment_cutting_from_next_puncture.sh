#!/usr/bin/env bash
# experiment_cutting_from_next_puncture.sh: the tuned preset's two calibration
# steps (as scripts/results_validation.sh) with --cutting-from-next-puncture,
# then the held-out cases (as scripts/results_heldout.sh):
# results/experiments/cutting_from_next_puncture/ (the preset, both
# calibration summaries, the held-out summary, README.md with the comparison
# against the committed preset). FEM references from out/.fem_cache (run
# scripts/results_validation.sh and scripts/results_heldout.sh first, or
# they are computed: about 2 min each on 2 cores).
#   bash scripts/experiment_cutting_from_next_puncture.sh      (RANKS=2)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/results_env.sh"
mpi=(mpirun --oversubscribe -np "${RANKS:-2}")
out=results/experiments/cutting_from_next_puncture
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$build/apps/puncture" calibrate scenes/default_force_law.json -o "$work/single_speed" --name single_speed \
  --integrator implicit --force-weight 4 --depth-weight 1 --surface-fit --cutting-from-next-puncture -q
"${mpi[@]}" "$build/apps/puncture" calibrate "$work/single_speed/single_speed.json" -o "$work/preset" \
  --name cutting_from_next_puncture --integrator implicit --force-weight 4 --depth-weight 1 --fem-speeds 1,10 \
  --keep K,breakthrough,cutting,friction,stiffening --cutting-from-next-puncture -q
"${mpi[@]}" "$build/apps/puncture" validate "$work/preset/cutting_from_next_puncture.json" \
  --cases validation/cases/default_heldout.json -o "$work/heldout" --no-vtk -q \
  --model-note "as results/tuned_preset, with --cutting-from-next-puncture in both calibration steps"
rm -rf "$out.new"; mkdir -p "$out.new"
cp "$work/preset/cutting_from_next_puncture.json" "$work/preset/cutting_from_next_puncture.provenance.json" "$out.new/"
cp "$work/single_speed/calibration_summary.md" "$out.new/single_speed_calibration_summary.md"
cp "$work/preset/calibration_summary.md" "$out.new/calibration_summary.md"
cp "$work/heldout/heldout_summary.md" "$work/heldout/heldout_summary.json" "$out.new/"
py="${PYTHON:-$(command -v /usr/bin/python3 || command -v python3)}"
"$py" - "$out.new" results/validation_heldout/heldout_summary.json "$(git rev-parse --short HEAD)" <<'PY'
import json, os, sys, datetime, platform
out, committed, rev = sys.argv[1:4]
new = json.load(open(os.path.join(out, "heldout_summary.json")))
old = json.load(open(committed))
def rows(s):
    return {(c["name"], l["layer"]): dict(l, held_out=c["held_out"]) for c in s["cases"] for l in c["layers"]}
a, b = rows(old), rows(new)
def count(r, held):
    return sum(1 for l in r.values() if l["accepted"] and l["held_out"] == held)
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "unknown CPU")
machine = f"{platform.node()} ({cpu}, {os.cpu_count()} cores)"
lines = ["# Experiment: the cutting force of a layer identified by the next layer's puncture", "",
         f"Made by `bash scripts/experiment_cutting_from_next_puncture.sh` at git {rev} on "
         f"{machine}, {datetime.datetime.now(datetime.timezone.utc).strftime('%Y-%m-%dT%H:%M:%SZ')}.", "",
         "The tuned preset's two calibration steps with `--cutting-from-next-puncture`: a layer whose next layer "
         "is met at the tip gets its cutting force tuned in that layer's stage, from that layer's puncture force "
         "and depth (on the FEM's 0.2 mm load steps the skin's own cut has too few samples, so by default its "
         "cutting force keeps its start G_c x 2a = 1.44 N). Then the same held-out cases. Committed preset: "
         "results/tuned_preset, results/validation_heldout.", "",
         f"Accepted layer-cases: in sample {count(b, False)} of 3 (committed preset {count(a, False)}); "
         f"held out {count(b, True)} of 12 (committed preset {count(a, True)}).", "",
         "| case | layer | force RMSE / peak: committed, this | puncture force error: committed, this | accepted: committed, this |",
         "|---|---|---|---|---|"]
def f(x):
    return "n/a" if x is None else f"{x:+.3f}"
for key in a:
    if key not in b: continue
    la, lb = a[key], b[key]
    lines.append(f"| {key[0]} | {key[1]} | {la['force_rmse_relative']:.3f}, {lb['force_rmse_relative']:.3f} | "
                 f"{f(la.get('puncture_force_error_relative'))}, {f(lb.get('puncture_force_error_relative'))} | "
                 f"{'yes' if la['accepted'] else 'no'}, {'yes' if lb['accepted'] else 'no'} |")
# A case whose parameters came by another rule in the two runs (the committed
# preset's slab rule; this preset has none of its own) compares the rules too.
rules = {c["name"]: (c.get("slab_rule"), c.get("rule")) for c in old["cases"]}
for c in new["cases"]:
    before = rules.get(c["name"])
    if before and before[0] and not c.get("slab_rule"):
        lines += ["", f"`{c['name']}`: the committed preset takes its parameters there from its slab rule "
                  f"({before[0]}); this preset has no slab rule of its own (that would need its own family of "
                  f"calibrations), so it keeps them ({c.get('rule') or 'the case file rule'}): that row compares the "
                  "rules as well as the option."]
lines += ["", "Files: the preset (`cutting_from_next_puncture.json`, provenance), both calibration summaries, "
          "`heldout_summary.md/.json` (every metric of every case).", ""]
open(os.path.join(out, "README.md"), "w").write("\n".join(lines))
PY
rm -rf "$out"; mv "$out.new" "$out"
echo "wrote $out"
