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
lags, cut_at_fat = [], []
for name, fat in (("default", 8.4), ("thick_fat", 25.2)):
    summary, rows = fem_metrics.read_fem(os.path.join(work, name))
    ev = {p["name"]: p for p in summary["punctures"]}
    sk, ft = ev.get("skin"), ev.get("fat")
    prof = [l.strip().split(",") for l in open(os.path.join(work, name, "fem_surface_profile.csv"))
            if not l.startswith(("#", "step"))]
    tent = None
    if sk:
        at = [p for p in prof if p[4] == "skin" and float(p[1]) <= sk["depth_mm"] + 1e-9]
        if at:
            last_depth = max(float(p[1]) for p in at)
            tent = -min(float(p[3]) for p in at if float(p[1]) == last_depth)
    fmt = lambda e: f"{e['force_N']:.2f} N at {e['depth_mm']:.1f} mm" if e else "none"
    gap = f"{ft['depth_mm'] - sk['depth_mm']:.1f}" if sk and ft else "n/a"
    lags.append(ft["depth_mm"] - sk["depth_mm"] if sk and ft else None)
    fat_cut = [float(r["cutting_force_N"]) for r in rows if r["phase"] == "insertion" and sk and ft
               and sk["depth_mm"] < float(r["depth_mm"]) <= ft["depth_mm"] + 1e-9]
    cut_at_fat.append(max(fat_cut) if fat_cut else None)
    L.append(f"| {name} | {fat:g} | {fmt(sk)} | {fmt(ft)} | {gap} | {tent:.2f} |" if tent is not None else
             f"| {name} | {fat:g} | {fmt(sk)} | {fmt(ft)} | {gap} | n/a |")
fat = json.load(open("scenes/default.json"))["layers"][1]
if all(l is not None and l < 1.0 for l in lags):
    L += ["", f"Reading: the fat punctures {lags[0]:.1f} mm after the skin in the default slab and {lags[1]:.1f} mm after it "
          "with three times the fat, so the near-coincidence does not come from a thin fat squeezed against the muscle. "
          "It comes from the fat itself: when the skin gives way the tip carries the skin's puncture force (about "
          f"{json.load(open(os.path.join(work, 'default', 'fem_summary.json')))['punctures'][0]['force_N']:.1f} N), far "
          f"more than a layer of the fat's strength and toughness ({fat['puncture']['cohesive_strength_kPa']:g} kPa, "
          f"{fat['puncture']['toughness_J_per_m2']:g} J/m^2, cutting force G_c x 2a = "
          f"{fat['puncture']['toughness_J_per_m2'] * 1.27e-3:.2f} N) and modulus ({fat['material']['youngs_modulus_kPa']:g} kPa) "
          "can resist, so the fat's crack opens as soon as the tip reaches it and the energy the skin stored is spent "
          "cutting it (the cutting column peaks at "
          + ", ".join(f"{c:.2f} N" for c in cut_at_fat if c is not None) + " between the two punctures). The FEM "
          "predicts no puncture of the fat of its own at either fat thickness tried under this skin; that is the physics of a "
          "soft, weak layer under a tough, stiffening one in this model, not an artefact of the slab's geometry."]
else:
    L += ["", "Reading: with the fat thicker the fat punctures on its own, "
          + ", ".join(f"{l:.1f} mm" for l in lags if l is not None) + " after the skin: the near-coincidence in the "
          "default slab comes from its thin fat squeezed between the tented skin and the muscle."]
open(out + ".part", "w").write("\n".join(L) + "\n")
os.replace(out + ".part", out)
print("wrote", out)
PY
