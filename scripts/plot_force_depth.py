#!/usr/bin/python3
"""Force-depth plot of a `puncture run` (and optionally a `puncture fem`) output.

usage: plot_force_depth.py RUN_DIR OUT.png [--fem FEM_DIR] [--title TEXT] [--note TEXT]

Reads RUN_DIR/realtime_curve.csv and RUN_DIR/summary.json (puncture events),
and FEM_DIR/fem_force_depth.csv if given. The note (e.g. command, machine,
date) is printed under the plot so the figure says how it was made.
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from results_io import read_csv_rows  # noqa: E402

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_csv(path):
    rows = read_csv_rows(path)
    if not rows:
        raise SystemExit(f"{path}: no rows")
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run_dir")
    ap.add_argument("out_png")
    ap.add_argument("--fem")
    ap.add_argument("--title", default="Needle force along the insertion")
    ap.add_argument("--note", default="")
    a = ap.parse_args()

    rows = read_csv(os.path.join(a.run_dir, "realtime_curve.csv"))
    with open(os.path.join(a.run_dir, "summary.json")) as f:
        summary = json.load(f)
    layers = [l["name"] for l in summary["layers"]]

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.6))
    depth = [float(r["depth_mm"]) for r in rows]
    force = [float(r["force_N"]) for r in rows]
    vel = [float(r["velocity_mm_per_s"]) for r in rows]
    ins = [i for i, v in enumerate(vel) if v > 0]
    wd = [i for i, v in enumerate(vel) if v < 0]
    ax1.plot([depth[i] for i in ins], [force[i] for i in ins], color="C0", lw=1.6, label="real-time model, insertion")
    ax1.plot([depth[i] for i in wd], [force[i] for i in wd], color="C0", lw=1.0, ls="--", label="real-time model, withdrawal")
    for e in summary["puncture_events"]:
        ax1.plot(e["depth_mm"], e["total_force_N"], "v", color="C3")
        ax1.annotate(f'{e["layer"]} breaks\n{e["depth_mm"]:.1f} mm, {e["total_force_N"]:.2f} N',
                     (e["depth_mm"], e["total_force_N"]), textcoords="offset points", xytext=(6, 6), fontsize=8)
    if a.fem:
        frows = read_csv(os.path.join(a.fem, "fem_force_depth.csv"))
        ax1.plot([float(r["depth_mm"]) for r in frows], [float(r["force_N"]) for r in frows],
                 color="C2", lw=1.6, label="FEM reference (quasi-static)")
    shown = list(force)
    if a.fem:
        shown += [float(r["force_N"]) for r in frows]
    span = max(shown) - min(0.0, min(shown))
    ax1.set_ylim(min(0.0, min(shown)) - 0.05 * span, max(shown) + 0.2 * span)
    cum = 0.0
    for name, layer in zip(layers, summary["settings"]["layers"]):
        ax1.axvline(cum, color="0.8", lw=0.8)
        ax1.text(cum, ax1.get_ylim()[1] * 0.02, f" {name}", fontsize=8, color="0.4", rotation=90, va="bottom")
        cum += layer["thickness_mm"]
    ax1.set_xlabel("tip depth below the skin surface (mm)")
    ax1.set_ylabel("needle force (N, + resists insertion)")
    ax1.set_title(a.title)
    ax1.legend(fontsize=8, loc="upper right")
    ax1.grid(alpha=0.3)

    t = [float(r["time_s"]) for r in rows]
    ax2.plot(t, force, color="C0", lw=1.4, label="total")
    if "tip_force_N" in rows[0]:
        # The force's parts: tip (surface force of the pressed layer), cutting, shaft friction (+ d h v).
        for key, label, color in (("tip_force_N", "tip (surface force)", "C3"), ("cutting_force_N", "cutting", "C1"),
                                  ("friction_force_N", "shaft friction + d h v", "C2")):
            ax2.plot(t, [float(r[key]) for r in rows], lw=1.0, color=color, label=label)
    else:
        for k, name in enumerate(layers):
            sf = [float(r[f"{name}_surface_force_N"]) for r in rows]
            df = [float(r[f"{name}_damping_force_N"]) for r in rows]
            ax2.plot(t, sf, lw=0.9, color=f"C{k + 3}", label=f"{name} surface force")
            ax2.plot(t, df, lw=0.9, ls=":", color=f"C{k + 3}", label=f"{name} damping d h v")
    ax2.set_xlabel("time (s)")
    ax2.set_ylabel("force (N)")
    ax2.set_title("Force parts along the trajectory")
    ax2.legend(fontsize=7, ncol=2)
    ax2.grid(alpha=0.3)
    if a.note:
        fig.text(0.01, 0.005, a.note, fontsize=7, color="0.35")
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    tmp = a.out_png + ".tmp.png"
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, a.out_png)


if __name__ == "__main__":
    main()
