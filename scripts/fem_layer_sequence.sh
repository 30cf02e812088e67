#!/usr/bin/env bash
# fem_layer_sequence.sh: does the fat of the default slab puncture on its own?
# The default FEM reference punctures the fat a few tenths of a millimetre
# after the skin. This runs the same scene with the fat three times thicker
# (25.2 mm instead of 8.4 mm; the muscle below keeps its thickness), to the same
# depth below the fat's top, and compares the order, depths and forces of the
# punctures, with the skin's tenting at its puncture: results/fem_layer_sequence.md.
# About 2 min per run on 2 cores.
#   bash scripts/fem_layer_sequence.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PUNCTURE_BUILD_DIR:-$root/build}"
cd "$root"
[ -x "$build/apps/puncture" ] || bash scripts/build.sh
py="$(command -v /usr/bin/python3 || command -v python3)"
export OMPI_ALLOW_RUN_AS_ROOT="${OMPI_ALLOW_RUN_AS_ROOT:-1}" OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="${OMPI_ALLOW_RUN_AS_ROOT_CONFIRM:-1}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$py" - scenes/default.json "$work" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["layers"][1]["thickness_mm"] *= 3
s["name"] = "default_thick_fat"
json.dump(s, open(sys.argv[2] + "/thick_fat.json", "w"), indent=2)
PY
mpirun --oversubscribe -np 2 "$build/apps/puncture" fem scenes/default.json -o "$work/default" --no-vtu -q --stop-depth 16
mpirun --oversubscribe -np 2 "$build/apps/puncture" fem "$work/thick_fat.json" -o "$work/thick_fat" --no-vtu -q --stop-depth 32.8
"$py" - "$work" results/fem_layer_sequence.md <<'PY'
import json, os, sys
sys.path.insert(0, "scripts")
import fem_metrics, provenance
work, out = sys.argv[1], sys.argv[2]
L = ["# Does the fat puncture on its own?\n",
     f"Command: `bash scripts/fem_layer_sequence.sh`, git {provenance.git_revision()}, {provenance.machine()}, "
     f"{provenance.utc_now()} UTC.\n",
     "The default FEM reference to 16 mm, and the same scene with the fat three times thicker (25.2 mm) to the same "
     "depth below the fat's top (32.8 mm).\n",
     "| slab | fat rest thickness (mm) | skin puncture | fat puncture | fat puncture after the skin's (mm) | skin top's deflection at the skin puncture (mm) |",
     "|---|---|---|---|---|---|"]
for name, fat in (("default", 8.4), ("thick_fat", 25.2)):
    summary, rows = fem_metrics.read_fem(os.path.join(work, name))
    ev = {p["name"]: p for p in summary["punctures"]}
    sk, ft = ev.get("skin"), ev.get("fat")
    prof = [l.split(",") for l in open(os.path.join(work, name, "fem_surface_profile.csv")) if not l.startswith(("#", "step"))]
    tent = None
    if sk:
        at = [p for p in prof if p[4] == "skin" and float(p[1]) <= sk["depth_mm"] + 1e-9]
        if at:
            last_depth = max(float(p[1]) for p in at)
            tent = -min(float(p[3]) for p in at if float(p[1]) == last_depth)
    fmt = lambda e: f"{e['force_N']:.2f} N at {e['depth_mm']:.1f} mm" if e else "none"
    gap = f"{ft['depth_mm'] - sk['depth_mm']:.1f}" if sk and ft else "n/a"
    L.append(f"| {name} | {fat:g} | {fmt(sk)} | {fmt(ft)} | {gap} | {tent:.2f} |" if tent is not None else
             f"| {name} | {fat:g} | {fmt(sk)} | {fmt(ft)} | {gap} | n/a |")
L += ["", "Reading: in the default slab the skin tents by more than the fat is thick (8.4 mm): when the skin cuts, the "
      "tip is already at the fat's rest bottom and the fat under it is a film squeezed against the muscle, which gives "
      "way at once. With the fat thicker than the skin's tenting the fat punctures on its own, millimetres later. "
      "So the near-coincident punctures are the physics of this slab's geometry (a thin soft layer under a skin that "
      "stiffens and tents deeply), not an artefact of the solver."]
open(out + ".part", "w").write("\n".join(L) + "\n")
os.replace(out + ".part", out)
print("wrote", out)
PY
