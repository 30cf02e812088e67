#!/usr/bin/python3
"""Plot of a `puncture calibrate` folder (matplotlib; run with /usr/bin/python3).

In:  DIR/calibration_curves.csv  (curve,time_s,depth_mm,force_N[,phase]; curve =
     fem or measured (the reference), before, after; a "# made by: ..." first line)
Out: DIR/calibration_force_depth.png  force against depth: the reference and the
     real-time model before and after calibration; insertion solid, withdrawal
     dashed (dwell at the deepest point joins them). The axes hold every curve
     (nothing clipped).
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
        phase = row.get("phase") or "insertion"
        c = curves.setdefault(row["curve"], {})
        part = c.setdefault("withdrawal" if phase == "withdrawal" else "insertion", ([], []))
        part[0].append(float(row["depth_mm"]))
        part[1].append(float(row["force_N"]))
    fig, ax = plt.subplots(figsize=(8.5, 5))
    style = {"before": dict(color="tab:gray", lw=1.2, label="real-time, before calibration"),
             "after": dict(color="tab:blue", lw=1.6, label="real-time, calibrated")}
    all_f, all_d = [], []
    for name, parts in curves.items():
        s = style.get(name, dict(color="black", lw=2.2, alpha=0.7, label=f"reference ({name})"))
        for phase, (d, f) in parts.items():
            kw = dict(s)
            if phase == "withdrawal":
                kw["ls"] = "--"
                kw["label"] = None
            elif name == "before":
                kw["ls"] = ":"
            ax.plot(d, f, **kw)
            all_f += f
            all_d += d
    if all_f:
        lo, hi = min(all_f), max(all_f)
        pad = 0.05 * max(hi - lo, 1e-9)
        ax.set_ylim(lo - pad, hi + pad)
        ax.set_xlim(min(all_d), max(all_d))
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_xlabel("needle depth below the skin surface (mm)")
    ax.set_ylabel("needle force (N)")
    ax.set_title("Calibration against the reference (solid: insertion, dashed: withdrawal)")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
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
