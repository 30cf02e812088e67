#!/usr/bin/python3
"""Plot of a `puncture calibrate` folder (matplotlib; run with /usr/bin/python3).

In:  DIR/calibration_curves.csv  (curve,time_s,depth_mm,force_N; curve = fem or
     measured (the reference), before, after; a "# made by: ..." first line)
Out: DIR/calibration_force_depth.png  force against depth: the reference and the
     real-time model before and after calibration (insertion phase)
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(folder):
    path = os.path.join(folder, "calibration_curves.csv")
    with open(path, newline="") as f:
        lines = f.readlines()
    note = lines[0][1:].strip() if lines and lines[0].startswith("#") else ""
    curves = {}
    for row in csv.DictReader(l for l in lines if not l.startswith("#")):
        c = curves.setdefault(row["curve"], ([], []))
        c[0].append(float(row["depth_mm"]))
        c[1].append(float(row["force_N"]))
    fig, ax = plt.subplots(figsize=(8, 4.8))
    style = {"before": dict(color="tab:gray", ls="--", lw=1.2, label="real-time, before calibration"),
             "after": dict(color="tab:blue", lw=1.6, label="real-time, calibrated")}
    for name, (d, f) in curves.items():
        if name in style:
            ax.plot(d, f, **style[name])
        else:
            ax.plot(d, f, color="black", lw=2.2, alpha=0.7, label=f"reference ({name})")
    ref = [n for n in curves if n not in style]
    if ref:
        d, f = curves[ref[0]]
        top = max(f) if f else 1.0
        ax.set_ylim(min(0.0, min(f)) - 0.05 * top, 1.6 * top)
        ax.set_xlim(min(d), max(d))
    ax.set_xlabel("needle depth below the skin surface (mm)")
    ax.set_ylabel("needle force (N)")
    ax.set_title("Calibration of the real-time model against the reference")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left")
    if note:
        fig.text(0.01, 0.005, note, fontsize=6, color="0.4")
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    out = os.path.join(folder, "calibration_force_depth.png")
    fig.savefig(out + ".part.png", dpi=130)
    os.replace(out + ".part.png", out)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: plot_calibration.py DIR")
    main(sys.argv[1])
