#!/usr/bin/python3
"""Plots of a `puncture compare` folder (matplotlib; run with /usr/bin/python3).

In:  DIR with comparison.csv, curves/<model>.csv, fem_curve.csv,
     deflection_profiles.csv (written by puncture compare).
Out: DIR/force_depth.png       force against depth of every model and the FEM
                               (insertion; withdrawal dashed where a model has it)
     DIR/pareto.png            force error against time per step (p99, log), the
                               Pareto front of accuracy and cost
     DIR/skin_deflection.png   skin surface deflection against the distance from
                               the needle, every model and the FEM, at one depth
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from results_io import number as num, pareto_front, read_csv_rows as read_rows, save_figure  # noqa: E402

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def phases(rows):
    """(insertion rows, withdrawal rows) by the sign of the velocity."""
    ins = [r for r in rows if num(r["velocity_mm_per_s"]) > 0]
    wd = [r for r in rows if num(r["velocity_mm_per_s"]) < 0]
    return ins, wd


def plot_force_depth(d, models):
    fig, (ax, zoom) = plt.subplots(1, 2, figsize=(12, 4.6))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    fem = read_rows(os.path.join(d, "fem_curve.csv"))
    fem_depth = [num(r["depth_mm"]) for r in fem]
    fem_force = [num(r["force_N"]) for r in fem]
    fem_peak = max([f for f in fem_force if math.isfinite(f)] + [1e-9])
    deepest = max([x for x in fem_depth if math.isfinite(x)] + [1.0])
    for i, m in enumerate(models):
        path = os.path.join(d, "curves", m + ".csv")
        if not os.path.exists(path):
            continue
        ins, wd = phases(read_rows(path))
        c = colours[i % len(colours)]
        for a in (ax, zoom):
            a.plot([num(r["depth_mm"]) for r in ins], [num(r["force_N"]) for r in ins], lw=1.0, color=c, label=m)
            if wd and a is ax:
                a.plot([num(r["depth_mm"]) for r in wd], [num(r["force_N"]) for r in wd], lw=0.8, ls="--", color=c)
    for a in (ax, zoom):
        a.plot(fem_depth, fem_force, "ko-", ms=2.5, lw=1.3, label="FEM reference")
        a.set_xlabel("needle tip depth (mm)")
        a.set_ylabel("needle force (N)")
        a.grid(alpha=0.3)
    ax.set_title("Force against depth (withdrawal dashed)")
    ax.set_yscale("symlog", linthresh=max(fem_peak / 10, 1e-4))
    zoom.set_title("Zoom on the FEM's scale (linear)")
    zoom.set_xlim(-0.5, min(deepest, 15.0))
    zoom.set_ylim(-0.2 * fem_peak, 3.0 * fem_peak)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    save_figure(fig, os.path.join(d, "force_depth.png"), dpi=120)
    plt.close(fig)


def plot_pareto(d, rows):
    fig, ax = plt.subplots(figsize=(7, 4.6))
    pts = []
    for r in rows:
        t = num(r["step_time_p99_ms"])
        e = num(r["force_rmse_relative"])
        if math.isfinite(t) and math.isfinite(e) and t > 0:
            pts.append((t, e, r["model"]))
    for t, e, m in pts:
        ax.plot(t, max(e, 1e-4), "o")
        ax.annotate(m, (t, max(e, 1e-4)), fontsize=7, xytext=(4, 3), textcoords="offset points")
    front = pareto_front(pts)
    if front:
        ax.step([p[0] for p in front], [max(p[1], 1e-4) for p in front], where="post", color="grey", lw=0.8,
                label="Pareto front")
    ax.axvline(1.0, color="red", lw=0.8, ls=":", label="1 ms haptic step")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("time per step, 99th percentile (ms)")
    ax.set_ylabel("force RMSE / FEM peak (insertion)")
    ax.set_title("Accuracy against cost (FEM: its own reference)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    fig.tight_layout()
    save_figure(fig, os.path.join(d, "pareto.png"), dpi=120)
    plt.close(fig)


def plot_deflection(d):
    path = os.path.join(d, "deflection_profiles.csv")
    if not os.path.exists(path):
        return
    rows = read_rows(path)
    fem_depths = sorted({num(r["depth_mm"]) for r in rows if r["model"] == "fem" and num(r["depth_mm"]) > 0})
    if not fem_depths:
        return
    # The deepest FEM profile every model also recorded, else the first.
    depth = fem_depths[0]
    for cand in fem_depths:
        if all(any(num(r["depth_mm"]) == cand for r in rows if r["model"] == m) for m in {r["model"] for r in rows}):
            depth = cand
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for m in sorted({r["model"] for r in rows}, key=lambda x: (x != "fem", x)):
        pr = [r for r in rows if r["model"] == m and num(r["depth_mm"]) == depth]
        if not pr:
            continue
        style = dict(color="k", lw=1.5, marker="o", ms=2.5) if m == "fem" else dict(lw=1.0)
        ax.plot([num(r["r_mm"]) for r in pr], [num(r["deflection_mm"]) for r in pr], label=m, **style)
    ax.set_xlabel("distance from the needle axis (mm)")
    ax.set_ylabel("skin deflection into the tissue (mm)")
    ax.set_title("Skin surface at needle depth %.2f mm (before the skin breaks)" % depth)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    save_figure(fig, os.path.join(d, "skin_deflection.png"), dpi=120)
    plt.close(fig)


def main():
    d = sys.argv[1]
    rows = read_rows(os.path.join(d, "comparison.csv"))
    models = [r["model"] for r in rows if r["model"] != "fem"]
    plot_force_depth(d, models)
    plot_pareto(d, rows)
    plot_deflection(d)


if __name__ == "__main__":
    main()
