#!/usr/bin/python3
"""fem_rate_study.py: the FEM reference's speed trend beside measured trends.

Reads FEM output folders of one scene run at several insertion speeds (as
written by scripts/fem_rate_study.sh) and writes OUT_DIR/README.md (a table
per speed: puncture force and depth of each layer, shaft friction per unit
length, force at the target depth, relaxation in the hold), OUT_DIR/rate.json
(the same numbers) and OUT_DIR/fem_rate_force_depth.png (force against
depth, one curve per speed), atomically.

Usage: fem_rate_study.py OUT_DIR SCENE_JSON COMMAND SPEED=FEM_DIR [SPEED=FEM_DIR ...]
"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import fem_metrics  # noqa: E402
import provenance  # noqa: E402
import results_io  # noqa: E402

MEASURED_TRENDS = [
    ("puncture force of cadaver skin and muscle (883 tests)", "relatively insensitive to penetration velocity",
     "Schneider, Peck & Melvin 1978, Univ. Michigan HSRI report UM-HSRI-78-23"),
    ("rupture force of porcine heart", "decreases for faster insertion (under conditions)",
     "Mahvash & Dupont 2009, Proc. IEEE ICRA 3097; 2010, IEEE TBME 57:934"),
    ("force to initiate penetration of lamb heart ex vivo", "decreases with needle velocity up to a critical velocity, "
     "then rate-independent", "Alja'afreh 2010, Proc. IMechE H 224:531"),
    ("penetration force of an artificial skin", "similar at 0.2 mm/s and at impulse speed",
     "Silva et al. 2018, J. Med. Devices 12:031007"),
    ("shaft force per unit length, PVC phantom", "rises with speed: 0.034 / 0.059 / 0.080 N/mm at 1 / 3 / 9 mm/s",
     "DiMaio & Salcudean 2003 (via van Gerwen et al. 2012, Fig. 6; ../shared/LITERATURE.md) [2nd]"),
    ("needle friction coefficient on a test bed", "0.12-0.34, rises with velocity, falls with pressure",
     "ASME MSEC 2021, paper V001T03A008"),
]


def run_numbers(summary, rows):
    fr = fem_metrics.friction_per_mm(summary, rows)
    relax = fem_metrics.dwell_relaxation(rows)
    ins = [r for r in rows if r["phase"] == "insertion"]
    return {
        "punctures": [{"layer": p["name"], "depth_mm": p["depth_mm"], "force_N": p["force_N"]}
                      for p in summary.get("punctures", [])],
        "friction_per_mm_N": fr[0] if fr else None,
        "friction_fit_mm": [fr[1], fr[2]] if fr else None,
        "force_at_target_N": fem_metrics.value(ins[-1], "force_N"),
        "friction_at_target_N": fem_metrics.value(ins[-1], "friction_force_N"),
        "hold_s": relax[2] if relax else None,
        "relaxed_fraction": relax[3] if relax else None,
        "wall_s": summary.get("wall_time_s"),
    }


def table(runs, layer_names):
    L = ["| speed (mm/s) | " + " | ".join(f"{n} puncture" for n in layer_names) +
         " | friction per mm (N/mm) | force at target (N) | of it friction (N) | relaxed fraction after the hold | FEM wall (s) |",
         "|---" * (len(layer_names) + 6) + "|"]
    for speed, n in runs:
        by = {p["layer"]: p for p in n["punctures"]}
        cells = [f"{by[x]['force_N']:.2f} N at {by[x]['depth_mm']:.1f} mm" if x in by else "none" for x in layer_names]
        fr = f"{n['friction_per_mm_N']:.3f}" if n["friction_per_mm_N"] is not None else "n/a"
        rel = (f"{n['relaxed_fraction']:.2f} after {n['hold_s']:.1f} s" if n["relaxed_fraction"] is not None else "no hold")
        wall = f"{n['wall_s']:.0f}" if n["wall_s"] else "n/a"
        L.append(f"| {speed:g} | " + " | ".join(cells) +
                 f" | {fr} | {n['force_at_target_N']:.2f} | {n['friction_at_target_N']:.2f} | {rel} | {wall} |")
    return L


def trend_sentence(runs, layer_names):
    """From the slowest to the fastest run: change of each puncture force and of the friction per mm."""
    lo, hi = runs[0], runs[-1]
    parts = []
    for name in layer_names:
        a = next((p for p in lo[1]["punctures"] if p["layer"] == name), None)
        b = next((p for p in hi[1]["punctures"] if p["layer"] == name), None)
        if a and b:
            parts.append(f"{name} puncture {a['force_N']:.2f} -> {b['force_N']:.2f} N ({100 * (b['force_N'] / a['force_N'] - 1):+.0f} %, "
                         f"depth {a['depth_mm']:.1f} -> {b['depth_mm']:.1f} mm)")
    fa, fb = lo[1]["friction_per_mm_N"], hi[1]["friction_per_mm_N"]
    if fa and fb:
        parts.append(f"friction per mm {fa:.3f} -> {fb:.3f} N/mm ({100 * (fb / fa - 1):+.0f} %)")
    return f"From {lo[0]:g} to {hi[0]:g} mm/s: " + "; ".join(parts) + "."


def reading(runs, layer_names):
    """The FEM's trends beside the measured ones, by their signs."""
    lo, hi = runs[0][1], runs[-1][1]
    def change(name):
        a = next((p["force_N"] for p in lo["punctures"] if p["layer"] == name), None)
        b = next((p["force_N"] for p in hi["punctures"] if p["layer"] == name), None)
        return None if not a or not b else b / a - 1
    ch = [c for c in (change(n) for n in layer_names) if c is not None]
    if not ch:
        return ""
    if min(ch) > 0.05:
        force = (f"The FEM's puncture forces rise with speed ({100 * min(ch):.0f}-{100 * max(ch):.0f} % over the range): "
                 "its layers are viscoelastic with their measured moduli taken as the instantaneous ones, so a slower "
                 "insertion lets them relax before they break. Measured puncture forces of cadaver skin and muscle are "
                 "reported insensitive to speed and those of heart tissue fall with it (table below), so this rise is a "
                 "prediction of the model's reading of the relaxation data, not a trend it was fitted to.")
    elif max(ch) < -0.05:
        force = "The FEM's puncture forces fall with speed, as measured in heart tissue (table below)."
    else:
        force = "The FEM's puncture forces change by less than 5 % over the range, as cadaver skin and muscle (table below)."
    fa, fb = lo["friction_per_mm_N"], hi["friction_per_mm_N"]
    fric = ""
    if fa and fb:
        fric = (f" Its shaft friction per mm rises with speed ({100 * (fb / fa - 1):+.0f} %), as the phantom's does "
                "(+135 % from 1 to 9 mm/s), here because the tissue behind the tip has less time to relax.")
    return force + fric


def plot(path, curves, note):
    fig, ax = plt.subplots(figsize=(8, 4.8))
    for speed, rows in curves:
        pts = [(fem_metrics.value(r, "depth_mm"), fem_metrics.value(r, "force_N")) for r in rows
               if r["phase"] == "insertion"]
        ax.plot([p[0] for p in pts], [p[1] for p in pts], label=f"{speed:g} mm/s")
    ax.set_xlabel("tip depth (mm)")
    ax.set_ylabel("needle force (N)")
    ax.set_title("FEM reference: insertion force at three speeds")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.text(0.01, 0.01, note, fontsize=6)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    results_io.save_figure(fig, path)


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    out_dir, scene_path, command = sys.argv[1:4]
    scene = json.load(open(scene_path))
    layer_names = [l["name"] for l in scene["layers"]]
    runs, curves = [], []
    for arg in sys.argv[4:]:
        speed, d = arg.split("=", 1)
        summary, rows = fem_metrics.read_fem(d)
        runs.append((float(speed), run_numbers(summary, rows)))
        curves.append((float(speed), rows))
    runs.sort(key=lambda r: r[0])
    curves.sort(key=lambda c: c[0])
    os.makedirs(out_dir, exist_ok=True)
    stamp = f"`{command}`, git {provenance.git_revision()}, {provenance.machine()}, {provenance.utc_now()} UTC"
    plot(os.path.join(out_dir, "fem_rate_force_depth.png"), curves, stamp.replace("`", ""))
    L = ["# FEM reference at three insertion speeds\n",
         f"Command: {stamp}.\n",
         f"Scene `{scene_path}` with `insertion.speed_mm_per_s` (and the withdrawal speed) set to each speed; "
         "everything else as the scene says (viscoelastic layers: `layers[].material.viscoelastic`).\n",
         "![force against depth at three speeds](fem_rate_force_depth.png)\n"]
    L += table(runs, layer_names)
    L += ["", trend_sentence(runs, layer_names), "", reading(runs, layer_names)]
    L += ["", "Friction per mm: slope of the friction column from 1 mm below the last puncture to the target "
          "depth. Relaxed fraction: force at the end of the hold over the force at the end of the insertion.", "",
          "## Measured speed trends\n", "| what | trend | source |", "|---|---|---|"]
    L += [f"| {w} | {t} | {s} |" for w, t, s in MEASURED_TRENDS]
    results_io.write_text(os.path.join(out_dir, "rate.json"),
          json.dumps({"scene": scene_path, "command": command, "runs": [dict(speed_mm_per_s=s, **n) for s, n in runs]},
                     indent=2) + "\n")
    results_io.write_text(os.path.join(out_dir, "README.md"), "\n".join(L) + "\n")
    print("wrote", out_dir)


if __name__ == "__main__":
    main()
