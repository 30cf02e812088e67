#!/usr/bin/python3
"""Plots of a `puncture validate` report folder (matplotlib; run with /usr/bin/python3).

In:  DIR with force_depth_aligned.csv, realtime_curve.csv, fem_force_depth.csv,
     deflection_profiles.csv, layer_metrics.csv (written by puncture validate).
Out: DIR/force_depth.png        force against depth, both models (insertion and withdrawal)
     DIR/deflection_profiles.png deflection against distance from the needle per layer,
                                 before and after breakthrough, both models
     DIR/layer_errors.png        per-layer force RMSE, puncture depth and force errors
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from results_io import number as num, read_csv_rows as read_rows, save_figure  # noqa: E402

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def insertion(rows):
    """Rows of the insertion phase: velocity > 0 up to the deepest sample."""
    depth = [num(r["depth_mm"]) for r in rows]
    if not depth:
        return []
    deepest = max(range(len(depth)), key=lambda i: depth[i])
    return [r for i, r in enumerate(rows[: deepest + 1]) if num(r["velocity_mm_per_s"]) > 0]


def withdrawal(rows):
    """Rows after the deepest sample with velocity < 0 (the withdrawal)."""
    depth = [num(r["depth_mm"]) for r in rows]
    if not depth:
        return []
    deepest = max(range(len(depth)), key=lambda i: depth[i])
    return [r for r in rows[deepest:] if num(r["velocity_mm_per_s"]) < 0]


def plot_force_depth(d):
    rt_all = read_rows(os.path.join(d, "realtime_curve.csv"))
    rt, rt_out = insertion(rt_all), withdrawal(rt_all)
    fem = read_rows(os.path.join(d, "fem_force_depth.csv"))
    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.plot([num(r["depth_mm"]) for r in rt], [num(r["force_N"]) for r in rt], lw=1.2, color="C0",
            label="real-time (SHF + MSM), insertion")
    if rt_out:
        ax.plot([num(r["depth_mm"]) for r in rt_out], [num(r["force_N"]) for r in rt_out], "--", lw=1.2, color="C0",
                label="real-time, withdrawal")
    ax.plot([num(r["depth_mm"]) for r in fem], [num(r["force_N"]) for r in fem], "o-", ms=2.5, lw=1.0, color="C1",
            label="FEM reference (insertion, then withdrawal)")
    ax.set_xlabel("needle tip depth (mm)")
    ax.set_ylabel("needle force (N)")
    ax.set_title("Force against depth (insertion and withdrawal)")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    save_figure(fig, os.path.join(d, "force_depth.png"), dpi=120)
    plt.close(fig)


def plot_profiles(d):
    rows = read_rows(os.path.join(d, "deflection_profiles.csv"))
    layers = []
    for r in rows:
        if r["layer"] not in layers:
            layers.append(r["layer"])
    if not layers:
        return
    fig, axes = plt.subplots(2, len(layers), figsize=(4 * len(layers), 6.5), squeeze=False)
    for col, layer in enumerate(layers):
        for row, phase in enumerate(["before_breakthrough", "after_breakthrough"]):
            ax = axes[row][col]
            for model, style in [("fem", "-"), ("realtime", "o--")]:
                sel = [r for r in rows if r["layer"] == layer and r["phase"] == phase and r["model"] == model]
                if sel:
                    ax.plot([num(r["r_mm"]) for r in sel], [num(r["deflection_mm"]) for r in sel], style, ms=4,
                            label=f"{model} (depth {num(sel[0]['depth_mm']):.2f} mm)")
            ax.set_title(f"{layer}: {phase.replace('_', ' ')}", fontsize=10)
            ax.set_xlabel("distance from the needle axis r (mm)")
            ax.set_ylabel("deflection into the tissue (mm)")
            ax.grid(alpha=0.3)
            if ax.lines:
                ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, os.path.join(d, "deflection_profiles.png"), dpi=110)
    plt.close(fig)


def plot_layer_errors(d):
    rows = read_rows(os.path.join(d, "layer_metrics.csv"))
    if not rows:
        return
    names = [r["layer"] for r in rows]
    panels = [("pressing_force_rmse_N", "pressing force RMSE (N)"), ("puncture_depth_error_mm", "puncture depth error (mm)"),
              ("puncture_force_error_N", "puncture force error (N)"), ("deflection_rmse_mm", "deflection RMSE (mm)")]
    fig, axes = plt.subplots(1, len(panels), figsize=(3.6 * len(panels), 3.6))
    for ax, (key, label) in zip(axes, panels):
        values = [num(r.get(key)) for r in rows]
        ax.bar(names, [0 if math.isnan(v) else v for v in values], color="tab:blue")
        for i, v in enumerate(values):
            if math.isnan(v):
                ax.text(i, 0, "n/a", ha="center", va="bottom", fontsize=8)
        ax.axhline(0, color="k", lw=0.6)
        ax.set_title(label, fontsize=10)
        ax.grid(axis="y", alpha=0.3)
    fig.suptitle("Per-layer errors (real-time minus FEM)")
    fig.tight_layout()
    save_figure(fig, os.path.join(d, "layer_errors.png"), dpi=110)
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plot_validation.py REPORT_DIR")
    d = sys.argv[1]
    plot_force_depth(d)
    plot_profiles(d)
    plot_layer_errors(d)


if __name__ == "__main__":
    main()
