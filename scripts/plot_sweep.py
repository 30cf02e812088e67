#!/usr/bin/python3
"""Pareto plot of a `puncture sweep` folder (matplotlib; run with /usr/bin/python3).

In:  DIR/accuracy_cost.csv (model, knob, value, status, force_rmse_N,
     time_per_step_s, time_p99_s, ...).
Out: DIR/pareto.png: force RMSE against the finest FEM versus time per step
     (real-time: mean tick over the ticks with contact, with a bar to its
     99th percentile; FEM: per load step), log axes, one marker series per
     knob, the non-dominated points joined.
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from results_io import number as num, pareto_front, read_csv_rows as read_rows, save_figure  # noqa: E402

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plot_sweep.py SWEEP_DIR")
    d = sys.argv[1]
    rows = [r for r in read_rows(os.path.join(d, "accuracy_cost.csv")) if r["status"] == "ok"]
    points = []
    for r in rows:
        t, e = num(r["time_per_step_s"]), num(r["force_rmse_N"])
        if t > 0 and math.isfinite(t) and math.isfinite(e):
            points.append((t, max(e, 1e-6), r))
    fig, ax = plt.subplots(figsize=(8, 5.5))
    knobs = []
    for _, _, r in points:
        key = (r["model"], r["knob"])
        if key not in knobs:
            knobs.append(key)
    markers = "osD^v<>ph*"
    for i, key in enumerate(knobs):
        sel = [(t, e, r) for t, e, r in points if (r["model"], r["knob"]) == key]
        sc = ax.scatter([p[0] for p in sel], [p[1] for p in sel], marker=markers[i % len(markers)], s=36,
                        label=f"{key[0]}: {key[1]}")
        for t, e, r in sel:
            p99 = num(r.get("time_p99_s"))
            if math.isfinite(p99) and p99 > t:
                ax.plot([t, p99], [e, e], color=sc.get_facecolor()[0], lw=0.8, alpha=0.6)
        for t, e, r in sel:
            ax.annotate(r["value"], (t, e), fontsize=7, xytext=(3, 3), textcoords="offset points")
    front = pareto_front(points)
    if len(front) > 1:
        ax.plot([p[0] for p in front], [p[1] for p in front], "k--", lw=0.8, label="Pareto front")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("time per step (s): real-time = mean tick over the ticks with contact, FEM = per load step")
    ax.set_ylabel("force RMSE against the finest FEM (N)")
    ax.set_title("What accuracy costs in time (bars: real-time tick mean to p99 over ticks with contact)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, os.path.join(d, "pareto.png"), dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
