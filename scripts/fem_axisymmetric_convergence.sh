#!/usr/bin/env bash
# fem_axisymmetric_convergence.sh: h- and p-convergence of the axisymmetric
# reference on the default slab, before the skin punctures.
#
# The default scene (bevel needle, Ogden layers, cohesive crack, friction)
# inserted to TARGET_MM (default 8 mm: the skin tents, it punctures at 9.4 mm)
# on meshes qD_n: degree D, n elements per needle radius (the path elements
# and the first element of every layer scale with them): Q1 with n = 4, 8, 16,
# 32 and Q2 with n = 4, 8, 16. The needle force at fixed depths (small and
# large indentation) is compared with its Richardson-extrapolated limit from
# the three finest Q1 meshes, and with the Q2 limit (p-refinement).
# Runs two meshes at a time (1 rank, 1 assembly thread each).
# Writes results/fem_axisymmetric_convergence.md and .png; each run's outputs
# stay in out/axisymmetric_convergence/<mesh>/.
#
# Usage: scripts/fem_axisymmetric_convergence.sh [BUILD_DIR]   (default: build)
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-$ROOT/build}
EXE=$BUILD/apps/puncture
SCENE=${SCENE:-$ROOT/scenes/default.json}
TARGET=${TARGET_MM:-8.0}
DEPTHS=${DEPTHS_MM:-"0.5 1 2 4 6 8"}
WORK=$ROOT/out/axisymmetric_convergence
OUT=$ROOT/results/fem_axisymmetric_convergence
mkdir -p "$WORK"
# The system interpreter has the Debian python3-matplotlib of scripts/setup.sh.
PY=${PYTHON:-$(command -v /usr/bin/python3 || command -v python3)}
trap 'rm -f "$OUT.md.part" "$OUT.png.part"' EXIT

CONFIGS=${CONFIGS:-"q1_4 q1_8 q1_16 q1_32 q2_4 q2_8 q2_16 q1_4_m12"}
for cfg in $CONFIGS; do
  "$PY" - "$SCENE" "$WORK/$cfg.json" "$TARGET" "$cfg" <<'EOF'
import json, sys
src, dst, target, cfg = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
deg, n, *variant = cfg.split("_")
s = json.load(open(src))
s["name"] = "convergence_" + cfg
s["insertion"]["target_depth_mm"] = target
s["insertion"]["dwell_s"] = 0.0
s["insertion"]["withdrawal_speed_mm_per_s"] = 1000.0  # withdrawal is not compared here
s["fem"]["element_degree"] = int(deg[1])
m = s["fem"]["mesh"]
base_n, base_path = m["elements_per_needle_radius"], m["path_element_size_mm"]
m["elements_per_needle_radius"] = int(n)
m["path_element_size_mm"] = base_path * base_n / int(n)
for v in variant:  # mK: K elements at least through every layer
    if v.startswith("m"):
        m["min_elements_per_layer"] = int(v[1:])
json.dump(s, open(dst, "w"), indent=1)
EOF
done
# Two runs at a time, one assembly thread each, so the two cores are used.
for cfg in $CONFIGS; do
  if [ ! -f "$WORK/$cfg/fem_summary.json" ] || [ -n "${RERUN:-}" ]; then echo "$cfg"; fi
done | PUNCTURE_FEM_THREADS=1 xargs -r -P2 -I{} sh -c \
  'echo "== {}: puncture fem $1/{}.json" >&2; "$2" fem "$1/{}.json" -o "$1/{}" > "$1/{}.log" 2>&1 || { echo "{} failed: see $1/{}.log" >&2; exit 1; }' \
  sh "$WORK" "$EXE"

SCRIPTS="$ROOT/scripts" "$PY" - "$WORK" "$OUT" "$TARGET" "$SCENE" "$DEPTHS" "$CONFIGS" <<'EOF'
import csv, json, sys, os, math
sys.path.insert(0, os.environ["SCRIPTS"])
import provenance
work, out, target, scene, depths, configs = sys.argv[1:]
depths = [float(d) for d in depths.split()]
configs = configs.split()
def curve(cfg):
    rows = [r for r in csv.DictReader(l for l in open(os.path.join(work, cfg, "fem_force_depth.csv")) if not l.startswith("#"))
            if r["phase"] == "insertion"]
    return [(float(r["depth_mm"]), float(r["force_N"])) for r in rows]
def at(c, d):
    for (d0, f0), (d1, f1) in zip(c, c[1:]):
        if d0 <= d <= d1 and d1 > d0:
            return f0 + (f1 - f0) * (d - d0) / (d1 - d0)
    return float("nan")
data = {cfg: curve(cfg) for cfg in configs}
summ = {cfg: json.load(open(os.path.join(work, cfg, "fem_summary.json"))) for cfg in configs}
F = {cfg: [at(data[cfg], d) for d in depths] for cfg in configs}
def rich(f1, f2, f3):
    # meshes h, h/2, h/4: observed order and extrapolated limit; not monotone: the finest value
    d12, d23 = f1 - f2, f2 - f3
    if d23 == 0 or d12 / d23 <= 1.0:
        return float("nan"), f3
    p = math.log2(d12 / d23)
    return p, f3 - d23 / (2 ** p - 1)
def family(deg):
    # configs of one degree, sorted by elements per needle radius
    return sorted((c for c in configs if c.startswith(f"q{deg}_") and c.count("_") == 1), key=lambda c: int(c.split("_")[1]))
def limit_of(deg):
    fam = family(deg)
    if len(fam) < 3:
        return None
    a, b, c = fam[-3:]
    return (a, b, c), [rich(F[a][i], F[b][i], F[c][i]) for i in range(len(depths))]
own = os.environ.get("SCENE_MESH", "q1_4")
rev, host, now = provenance.git_revision(), provenance.machine(), provenance.utc_now()
L = ["# Axisymmetric FEM: convergence of the needle force before the skin punctures\n",
     f"Command: `scripts/fem_axisymmetric_convergence.sh` (TARGET_MM={target}, DEPTHS_MM=\"{' '.join(f'{d:g}' for d in depths)}\", "
     f"scene {os.path.relpath(scene)}), git {rev}.  ",
     f"Machine: {host}; the runs went two at a time (1 rank and 1 assembly thread each), so wall times are indicative.  ",
     f"Date: {now} UTC.\n",
     f"The default scene (12 degree bevel, Ogden layers, cohesive crack along the path, shaft friction) inserted to "
     f"{target} mm, before the skin punctures (at 9.4 mm, results/fem_vs_literature.md), on meshes qD_n: element degree D, n elements per needle "
     "radius (the radial size under and around the needle, and the first element height at every layer top; the "
     "element height along the needle path scales with it: 0.4 mm x 4 / n). This refines where the error is: under the "
     "tip, through every layer (each layer starts with the tip element size at its top) and along the path; every "
     "step halves every element near the needle (uniform h-refinement of the region that carries the load). Q1 vs Q2 "
     "is the p-refinement. The force is read at fixed tip depths, from small indentation (0.5 mm, a few mN) to large "
     f"(8 mm, about 2 N). The scene's own mesh is **{own}**; q1_4_m12 is that mesh with 12 instead of 6 elements "
     "at least through every layer (a variant at the same n, not part of the extrapolation).\n"]
hdr = "| mesh | cells | dofs | Newton its | wall (s) | " + " | ".join(f"F({d:g} mm) N" for d in depths) + " |"
L += [hdr, "|" + "---|" * (5 + len(depths))]
for cfg in configs:
    s = summ[cfg]
    L.append(f"| {cfg} | {s['n_cells']} | {s['n_dofs']} | {s.get('newton_iterations', '')} | {s['wall_time_s']:.0f} | "
             + " | ".join(f"{x:.5g}" for x in F[cfg]) + " |")
lims = {}
for deg in (1, 2):
    r = limit_of(deg)
    if r is None:
        continue
    trio, res = r
    lims[deg] = [l for _, l in res]
    L.append(f"| **limit Q{deg}** (Richardson of {', '.join(trio)}) | | | | | " + " | ".join(f"**{l:.5g}**" for l in lims[deg]) + " |")
    L.append(f"| observed order p (Q{deg}) | | | | | " + " | ".join(f"{p:.2f}" for p, _ in res) + " |")
ref = None
if 1 in lims:
    ref = lims[1]
    L.append("\n**The limit** is the Richardson extrapolation of the three finest Q1 meshes (observed order p from the "
             "same three). Where those three forces are not monotone in h (p = nan) the limit is the finest Q1 value: "
             "there the differences between meshes are at the level of the contact resolution (crack-face nodes entering "
             "contact one by one under the bevel), not a smooth discretisation error, and extrapolation does not apply.")
    if 2 in lims:
        L.append("\nThe Q2 meshes converge from below, the Q1 meshes (apart from contact-resolution wiggles) from above; "
                 "the Q1 and Q2 limits differ by: "
                 + ", ".join(f"{d:g} mm {100 * (lims[2][i] / ref[i] - 1):+.1f} %" for i, d in enumerate(depths)) + ".")
    L.append("\nDeviation from the Q1 limit (%):\n")
    L += ["| mesh | " + " | ".join(f"{d:g} mm" for d in depths) + " | worst |", "|" + "---|" * (len(depths) + 2)]
    worst = {}
    for cfg in configs:
        devs = [100 * (F[cfg][i] / ref[i] - 1) for i in range(len(depths))]
        worst[cfg] = max(abs(x) for x in devs)
        name = f"**{cfg}** (scene)" if cfg == own else cfg
        L.append(f"| {name} | " + " | ".join(f"{x:+.2f}" for x in devs) + f" | {worst[cfg]:.2f} |")
    if 2 in lims:
        L.append("\nDeviation from the Q2 limit (%):\n")
        L += ["| mesh | " + " | ".join(f"{d:g} mm" for d in depths) + " | worst |", "|" + "---|" * (len(depths) + 2)]
        for cfg in configs:
            devs = [100 * (F[cfg][i] / lims[2][i] - 1) for i in range(len(depths))]
            name = f"**{cfg}** (scene)" if cfg == own else cfg
            L.append(f"| {name} | " + " | ".join(f"{x:+.2f}" for x in devs) + f" | {max(abs(x) for x in devs):.2f} |")
    if own in worst:
        ok = worst[own] <= 3.0
        L.append(f"\n**Verdict:** the scene's mesh {own} is within {worst[own]:.2f} % of the Q1 limit at every depth "
                 f"({'meets' if ok else 'misses'} the 3 % target)"
                 + (f"; against the Q2 limit its worst deviation is "
                    f"{max(abs(100 * (F[own][i] / lims[2][i] - 1)) for i in range(len(depths))):.2f} %." if 2 in lims else "."))
        var = [c for c in configs if c.startswith(own + "_")]
        if var:
            L.append("Meshes at the same n but laid out differently (" + ", ".join(var) + ") deviate by up to "
                     + ", ".join(f"{worst[c]:.2f} %" for c in var) + ": at 1-2 mm, where a few crack-face nodes carry "
                     "the contact, the layout of the nodes under the bevel matters as much as their spacing, so the "
                     "error there is of the order of these few per cent for every mesh coarser than q1_16.")
open(out + ".md.part", "w").write("\n".join(L) + "\n")
try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.4))
    for cfg in configs:
        c = data[cfg]
        ax[0].semilogy([x for x, _ in c if x > 0], [y for x, y in c if x > 0], label=cfg, lw=2.2 if cfg == own else 1.0)
    ax[0].set_xlabel("tip depth (mm)"); ax[0].set_ylabel("needle force (N), log scale"); ax[0].legend(); ax[0].grid(alpha=.3)
    ax[0].set_title("force-depth before the skin puncture")
    if ref:
        for cfg in configs:
            ax[1].plot(depths, [100 * (F[cfg][i] / ref[i] - 1) for i in range(len(depths))], "o-" if cfg.startswith("q1") else "s--",
                       label=cfg + (" (scene)" if cfg == own else ""), lw=2.2 if cfg == own else 1.0)
        ax[1].axhspan(-3, 3, color="g", alpha=.1, label="±3 %")
        ax[1].set_xlabel("tip depth (mm)"); ax[1].set_ylabel("deviation from the Q1 Richardson limit (%)")
        ax[1].legend(fontsize=8, ncol=2); ax[1].grid(alpha=.3)
    fig.suptitle(f"scripts/fem_axisymmetric_convergence.sh, git {rev}, {now} UTC, {host}", fontsize=8)
    fig.tight_layout(); fig.savefig(out + ".png.part", format="png", dpi=110)
except ImportError:
    pass
EOF
mv "$OUT.md.part" "$OUT.md"
[ -f "$OUT.png.part" ] && mv "$OUT.png.part" "$OUT.png"
echo "wrote $OUT.md"
