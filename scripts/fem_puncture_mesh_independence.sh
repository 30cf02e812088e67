#!/usr/bin/env bash
# fem_puncture_mesh_independence.sh: is the axisymmetric reference's skin
# puncture (force and depth) independent of the mesh?
#
# The default scene, inserted to TARGET_MM (default 14 mm: past the skin and
# fat punctures) on two meshes: the default's (elements_per_needle_radius and
# path_element_size_mm from the scene) and one twice as fine in both. Same
# load step, same physics; the runs stop at TARGET_MM (no hold: a hold that
# starts on the step where the muscle has just broken can stall Newton). Writes results/fem_puncture_mesh_independence.md
# (table + the command, machine and date) and keeps each run's outputs in
# out/mesh_independence/<mesh>/.
#
# Usage: scripts/fem_puncture_mesh_independence.sh [BUILD_DIR]   (default: build)
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-$ROOT/build}
EXE=$BUILD/apps/puncture
SCENE=${SCENE:-$ROOT/scenes/default.json}
TARGET=${TARGET_MM:-14}
WORK=$ROOT/out/mesh_independence
OUT=$ROOT/results/fem_puncture_mesh_independence.md
mkdir -p "$WORK"
# The system interpreter has the Debian python3-matplotlib of scripts/setup.sh.
PY=${PYTHON:-$(command -v /usr/bin/python3 || command -v python3)}
trap 'rm -f "$OUT.part"' EXIT

for mesh in default fine; do
  "$PY" - "$SCENE" "$WORK/$mesh.json" "$TARGET" "$mesh" <<'EOF'
import json, sys
src, dst, target, mesh = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
s = json.load(open(src))
s["name"] = "mesh_independence_" + mesh
s["insertion"]["target_depth_mm"] = target
s["insertion"]["dwell_s"] = 0.04
m = s["fem"]["mesh"]
if mesh == "fine":
    m["elements_per_needle_radius"] = 2 * m["elements_per_needle_radius"]
    m["path_element_size_mm"] = 0.5 * m["path_element_size_mm"]
json.dump(s, open(dst, "w"), indent=1)
EOF
  echo "== mesh $mesh: puncture fem $WORK/$mesh.json" >&2
  "$EXE" fem "$WORK/$mesh.json" -o "$WORK/$mesh" --stop-depth "$TARGET" >&2
done

"$PY" - "$WORK" "$OUT.part" "$TARGET" "$SCENE" <<'EOF'
import json, sys, datetime, platform, os, subprocess
work, out, target, scene = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4]
rows = {}
for mesh in ("default", "fine"):
    j = json.load(open(os.path.join(work, mesh, "fem_summary.json")))
    s = json.load(open(os.path.join(work, mesh + ".json")))
    ev = {p["name"]: p for p in j.get("punctures", [])}
    rows[mesh] = (s["fem"]["mesh"], j, ev)
def event(ev, layer):
    p = ev.get(layer)
    if p is None: return None
    return float(p["depth_mm"]), float(p["force_N"])
cpu = "unknown"
try:
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"): cpu = line.split(":", 1)[1].strip(); break
except OSError: pass
try: rev = subprocess.check_output(["git", "-C", os.path.dirname(scene), "rev-parse", "--short", "HEAD"], text=True).strip()
except Exception: rev = "unknown"
L = []
L.append("# Axisymmetric FEM: skin puncture on two meshes\n")
L.append(f"Command: `scripts/fem_puncture_mesh_independence.sh` (TARGET_MM={target}, scene {os.path.relpath(scene)}), git {rev}.  ")
L.append(f"Machine: {platform.system()} {platform.release()} {platform.machine()}, {os.cpu_count()} cores ({cpu}).  ")
L.append(f"Date: {datetime.datetime.utcnow().strftime('%Y-%m-%d %H:%M')} UTC.\n")
L.append("The default scene (Ogden layers, fracture-energy puncture, shaft friction, 12 degree bevel) inserted to "
         f"{target} mm on the scene's mesh and on one twice as fine (tip elements and path elements halved). "
         "Same load step: the depths are resolved to the step (and its cuts).\n")
L.append("| mesh | elements per needle radius | path element (mm) | cells | dofs | skin puncture force (N) | skin depth (mm) | fat puncture force (N) | fat depth (mm) | wall time (s) |")
L.append("|---|---|---|---|---|---|---|---|---|---|")
vals = {}
for mesh in ("default", "fine"):
    m, j, ev = rows[mesh]
    sk, ft = event(ev, "skin"), event(ev, "fat")
    vals[mesh] = (sk, ft)
    f = lambda x, i: f"{x[i]:.4g}" if x else "none"
    L.append(f"| {mesh} | {m['elements_per_needle_radius']} | {m['path_element_size_mm']} | {j['n_cells']} | {j['n_dofs']} | "
             f"{f(sk,1)} | {f(sk,0)} | {f(ft,1)} | {f(ft,0)} | {j['wall_time_s']:.0f} |")
sk0, sk1 = vals["default"][0], vals["fine"][0]
L.append("")
if sk0 and sk1:
    df = abs(sk0[1] - sk1[1]) / sk1[1] * 100
    dd = abs(sk0[0] - sk1[0]) / sk1[0] * 100
    verdict = "within" if max(df, dd) <= 10 else "NOT within"
    L.append(f"Skin puncture: force differs by {df:.2f} %, depth by {dd:.2f} % between the two meshes: {verdict} the 10 % aim.")
else:
    L.append("Skin puncture missing on one of the meshes: NOT mesh-independent.")
L.append("\nMeasured skin puncture forces for needles of this size: 0.5-3 N, median 1.22 N over 24 studies "
         "(../shared/LITERATURE.md); the reference sits at the upper end because the 60 mm slab lets the skin tent "
         "deeply before it cuts (the depth at puncture is large for the same reason).")
open(out, "w").write("\n".join(L) + "\n")
EOF
mv "$OUT.part" "$OUT"
echo "wrote $OUT"
