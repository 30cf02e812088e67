#!/usr/bin/python3
"""Plot of a `puncture calibrate` folder (matplotlib; run with /usr/bin/python3).

In:  DIR/calibration_curves.csv  (curve,time_s,depth_mm,force_N[,phase]; curve =
     fem or measured (the reference), before, after; a "# made by: ..." first line)
Out: DIR/calibration_force_depth.png  force against depth: the reference and the
     real-time model before and after calibration; insertion solid, withdrawal
     dashed (dwell at the deepest point joins them). The axes hold every curve
     (nothing clipped).
     With DIR/surface_identification.csv (calibrate --surface-fit):
     DIR/surface_identification.png, per identified layer the FEM's surface
     deflection (lines) and the identified force mesh's ring deflections
     (markers) at up to six contact deflections, and the tip force against
     the contact deflection, FEM and mesh.
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import results_io  # noqa: E402  (scripts/, beside this file)


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
    results_io.save_figure(fig, os.path.join(folder, "calibration_force_depth.png"), dpi=130)


def plot_surface_identification(folder):
    path = os.path.join(folder, "surface_identification.csv")
    if not os.path.exists(path):
        return
    with open(path, newline="") as f:
        lines = f.readlines()
    note = lines[0][1:].strip() if lines and lines[0].startswith("#") else ""
    layers = {}
    for row in csv.DictReader(l for l in lines if not l.startswith("#")):
        samples = layers.setdefault(row["layer"], {})
        s = samples.setdefault(int(row["sample"]), {"z0": float(row["contact_deflection_mm"]),
                                                    "fem_F": float(row["fem_force_N"]),
                                                    "model_F": float(row["model_force_N"]), "r": [], "fem": [], "model": []})
        s["r"].append(float(row["r_mm"]))
        s["fem"].append(float(row["fem_deflection_mm"]))
        s["model"].append(float(row["model_deflection_mm"]))
    if not layers:
        return
    fig, axes = plt.subplots(len(layers), 2, figsize=(11, 4 * len(layers)), squeeze=False)
    for row_axes, (name, samples) in zip(axes, layers.items()):
        keys = sorted(samples)
        shown = keys if len(keys) <= 6 else [keys[round(i * (len(keys) - 1) / 5)] for i in range(6)]
        colours = plt.cm.viridis([i / max(1, len(shown) - 1) for i in range(len(shown))])
        for c, k in zip(colours, shown):
            s = samples[k]
            row_axes[0].plot([0.0] + s["r"], [s["z0"]] + s["fem"], color=c, lw=1.6, label=f"FEM, z0 = {s['z0']:.1f} mm")
            row_axes[0].plot([0.0] + s["r"], [s["z0"]] + s["model"], "o--", color=c, ms=4, lw=0.8)
        row_axes[0].set_xlabel("distance from the needle axis r (mm)")
        row_axes[0].set_ylabel("deflection into the tissue (mm)")
        row_axes[0].set_title(f"{name}: surface, FEM (lines) and force mesh (markers)")
        row_axes[0].legend(fontsize=7)
        row_axes[0].grid(alpha=0.3)
        z0 = [samples[k]["z0"] for k in keys]
        row_axes[1].plot(z0, [samples[k]["fem_F"] for k in keys], "-", color="black", label="FEM tip force")
        row_axes[1].plot(z0, [samples[k]["model_F"] for k in keys], "o", color="tab:blue", ms=4,
                         label="force mesh (Eq. 5)")
        row_axes[1].set_xlabel("contact deflection z0 (mm)")
        row_axes[1].set_ylabel("force (N)")
        row_axes[1].set_title(f"{name}: pressing force")
        row_axes[1].legend(fontsize=8)
        row_axes[1].grid(alpha=0.3)
    if note:
        fig.text(0.01, 0.005, note, fontsize=6, color="0.4")
    fig.tight_layout(rect=(0, 0.02, 1, 1))
    results_io.save_figure(fig, os.path.join(folder, "surface_identification.png"), dpi=110)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: plot_calibration.py DIR")
    main(sys.argv[1])
    plot_surface_identification(sys.argv[1])
