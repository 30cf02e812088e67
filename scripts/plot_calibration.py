#!/usr/bin/python3
"""Plot of a `puncture calibrate` folder (matplotlib; run with /usr/bin/python3).

In:  DIR/calibration_curves.csv  (curve,time_s,depth_mm,force_N[,phase]; curve =
     fem or measured (the reference), before, after, the further references' and
     held-out recordings' series with "@<speed>mm_per_s[#n]" (held_out@..., before@...,
     after@...); a "# made by: ..." first line)
Out: DIR/calibration_force_depth.png  force against depth: the reference and the
     real-time model before and after calibration; insertion solid, withdrawal
     dashed (dwell at the deepest point joins them). The axes hold every curve
     (nothing clipped).
     Several recordings: one colour per recording (reference thick and pale, held out
     dashed-dotted, the calibrated model thin), the models before omitted but for the first.
     With DIR/repeat_scatter.csv (several recordings): DIR/repeat_scatter.png, per
     speed with two or more recordings the band of their insertion forces (min to max),
     their mean and the calibrated model.
     With DIR/surface_identification.csv (calibrate --surface-fit):
     DIR/surface_identification.png, per identified layer the FEM's surface
     deflection (lines) and the identified force mesh's ring deflections
     (markers) at up to six contact deflections, and the tip force against
     the contact deflection, FEM and mesh.
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import results_io  # noqa: E402  (scripts/, beside this file)


def main(folder):
    path = os.path.join(folder, "calibration_curves.csv")
    comments, rows = results_io.read_csv_comments(path)
    note = comments[0] if comments else ""
    curves = {}
    for row in rows:
        phase = row.get("phase") or "insertion"
        c = curves.setdefault(row["curve"], {})
        part = c.setdefault("withdrawal" if phase == "withdrawal" else "insertion", ([], []))
        part[0].append(float(row["depth_mm"]))
        part[1].append(float(row["force_N"]))
    fig, ax = plt.subplots(figsize=(8.5, 5))
    suffixes = []
    for name in curves:
        suffix = name[name.index("@"):] if "@" in name else ""
        if suffix not in suffixes:
            suffixes.append(suffix)
    colours = plt.cm.tab10.colors
    all_f, all_d = [], []
    for name, parts in curves.items():
        base, suffix = (name.split("@", 1) + [""])[:2]
        suffix = "@" + suffix if suffix else ""
        i = suffixes.index(suffix)
        several = len(suffixes) > 1
        if base == "before" and several and i > 0:
            continue
        tag = f" {suffix[1:].replace('mm_per_s', ' mm/s')}" if suffix else ""
        if base == "before":
            s = dict(color="tab:gray", lw=1.2, label="real-time, before calibration")
        elif base == "after":
            s = dict(color=colours[i % 10] if several else "tab:blue", lw=1.6, label="real-time, calibrated" + tag)
        else:
            s = dict(color=colours[i % 10] if several else "black", lw=2.2, alpha=0.4 if several else 0.7,
                     label=f"{'held out' if base == 'held_out' else 'reference (' + base + ')'}{tag}")
        for phase, (d, f) in parts.items():
            kw = dict(s)
            if phase == "withdrawal":
                kw["ls"] = "--"
                kw["label"] = None
            elif base == "before":
                kw["ls"] = ":"
            elif base == "held_out":
                kw["ls"] = "-."
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


def plot_repeat_scatter(folder):
    path = os.path.join(folder, "repeat_scatter.csv")
    if not os.path.exists(path):
        return
    comments, rows = results_io.read_csv_comments(path)
    note = comments[0] if comments else ""
    groups = {}
    for row in rows:
        g = groups.setdefault(row["group"], {"speed": float(row["speed_mm_per_s"]), "d": [], "lo": [], "hi": [],
                                              "mean": [], "model": []})
        for key, col in (("d", "depth_mm"), ("lo", "band_min_N"), ("hi", "band_max_N"), ("mean", "mean_N"),
                         ("model", "model_N")):
            g[key].append(float(row[col]))
    if not groups:
        return
    fig, axes = plt.subplots(1, len(groups), figsize=(6 * len(groups), 4.5), squeeze=False)
    for ax, g in zip(axes[0], groups.values()):
        ax.fill_between(g["d"], g["lo"], g["hi"], color="tab:orange", alpha=0.3, label="repeats: min to max")
        ax.plot(g["d"], g["mean"], color="tab:orange", lw=1.2, label="repeats: mean")
        ax.plot(g["d"], g["model"], color="tab:blue", lw=1.6, label="real-time, calibrated")
        ax.set_title(f"{g['speed']:.3g} mm/s: the scatter of the repeats")
        ax.set_xlabel("needle depth from contact (mm)")
        ax.set_ylabel("insertion force (N)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    if note:
        fig.text(0.01, 0.005, note, fontsize=6, color="0.4")
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    results_io.save_figure(fig, os.path.join(folder, "repeat_scatter.png"), dpi=120)


def plot_surface_identification(folder):
    path = os.path.join(folder, "surface_identification.csv")
    if not os.path.exists(path):
        return
    comments, rows = results_io.read_csv_comments(path)
    note = comments[0] if comments else ""
    layers = {}
    for row in rows:
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
    plot_repeat_scatter(sys.argv[1])
    plot_surface_identification(sys.argv[1])
