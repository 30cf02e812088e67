#!/usr/bin/python3
"""oblique_insertion.py: the real-time model with the needle at an angle to the surface normal.

The tuned preset (the model the app and every validation run), its sample widened
to WIDTH mm and its target depth set to DEPTH mm so that every angle's path fits
(the scene reader refuses a path whose tip or reached force mesh leaves the
sample), run by `puncture run` at 0, 15, 30, 45 and 60 deg. Per angle and layer:
the puncture's vertical depth and depth along the needle, the layer's load along
its surface normal at the break (the force mesh's), the needle's force along its
axis and across it then; per angle the peaks and the largest moment about the
entry point. The plot: force along and across the needle against the depth
along the needle.

What the numbers can be checked against: the frictionless tip (core/README.md,
"The needle at an angle") predicts, on the flat slab, the same normal load and
vertical depth at every break, the axial tip force F cos a and the lateral
F sin a; the page prints these ratios. The 3D FEM reference at an angle is so
far a blunt flat punch (results/fem_oblique_blunt/), so no figure here is
validated against a reference.

Usage: oblique_insertion.py PRESET OUT_DIR PUNCTURE_BIN [--width-mm 100] [--depth-mm 25]
Writes OUT_DIR/README.md, OUT_DIR/oblique_insertion.csv, OUT_DIR/oblique_insertion.png.
"""
import argparse
import json
import math
import os
import subprocess
import tempfile
import time

import provenance
import results_io

ANGLES = (0, 15, 30, 45, 60)


def scene_at(preset, angle, width_mm, depth_mm, speed_scale=1.0, name=None):
    s = json.loads(json.dumps(preset))
    s["name"] = name or f"{preset['name']}_{angle}deg"
    s["sample"]["diameter_mm"] = width_mm
    s["insertion"]["target_depth_mm"] = depth_mm
    s["insertion"]["angle_deg"] = float(angle)
    for key in ("speed_mm_per_s", "withdrawal_speed_mm_per_s"):
        if key in s["insertion"]:
            s["insertion"][key] *= speed_scale
    return s


def run_angle(binary, scene, work):
    """`puncture run` of SCENE: (summary, curve rows)."""
    path = os.path.join(work, scene["name"] + ".json")
    with open(path, "w") as f:
        json.dump(scene, f, indent=1)
    out = os.path.join(work, scene["name"])
    subprocess.run([binary, "run", path, "-o", out, "--no-frames", "-q"], check=True)
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    return summary, results_io.read_csv_rows(os.path.join(out, "realtime_curve.csv"))


def break_rows(angle, summary, curve, axial_summary):
    """One row per puncture: depths, normal load, axial force at the break; the lateral force and the layer's
    load on the tick before it; the axial needle at the normal speed v cos a: its break's depth and load."""
    index = {float(r["time_s"]): i for i, r in enumerate(curve)}
    axial = {e["layer"]: e for e in axial_summary["puncture_events"]}
    rows = []
    for e in summary["puncture_events"]:
        i = index.get(e["time_s"])
        before = curve[i - 1] if i else None
        ref = axial.get(e["layer"])
        rows.append({"angle_deg": angle, "layer": e["layer"], "depth_mm": e["depth_mm"],
                     "path_depth_mm": e["depth_mm"] / math.cos(math.radians(angle)),
                     "normal_load_N": e["surface_force_N"], "axial_force_N": e["total_force_N"],
                     "lateral_before_N": None if before is None else float(before["lateral_force_N"]),
                     "layer_load_before_N": None if before is None else float(before[e["layer"] + "_surface_force_N"]),
                     "axial_needle_depth_mm": None if ref is None else ref["depth_mm"],
                     "axial_needle_normal_load_N": None if ref is None else ref["surface_force_N"]})
    return rows


def peaks(curve):
    def col(name):
        return [float(r[name]) for r in curve]
    torque = [math.hypot(float(r["torque_x_N_m"]), math.hypot(float(r["torque_y_N_m"]), float(r["torque_z_N_m"])))
              for r in curve]
    axial, path = col("force_N"), col("path_depth_mm")
    at = max(range(len(axial)), key=axial.__getitem__)
    return {"peak_axial_N": axial[at], "peak_axial_path_mm": path[at], "peak_lateral_N": max(col("lateral_force_N")),
            "peak_torque_N_mm": 1e3 * max(torque)}


def plot(curves, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.2), sharex=True)
    for angle, curve in curves.items():
        ins = [r for r in curve if r["phase"] == "insertion"]
        depth = [float(r["path_depth_mm"]) for r in ins]
        ax.plot(depth, [float(r["force_N"]) for r in ins], label=f"{angle} deg", lw=1.2)
        bx.plot(depth, [float(r["lateral_force_N"]) for r in ins], label=f"{angle} deg", lw=1.2)
    ax.set(xlabel="tip depth along the needle (mm)", ylabel="force along the needle (N)",
           title="along the needle (> 0 resisting)")
    bx.set(xlabel="tip depth along the needle (mm)", ylabel="force across the needle (N)", title="across the needle")
    for a in (ax, bx):
        a.grid(alpha=0.3)
        a.set_xlim(left=-1)
    ax.legend()
    fig.tight_layout()
    results_io.save_figure(fig, path)


def page(args, rows, peak_rows, wall_s):
    lines = ["# The needle at an angle: the real-time model", "",
             f"- Command: `scripts/oblique_insertion.py {args.preset} {args.out_dir} <puncture> "
             f"--width-mm {args.width_mm:g} --depth-mm {args.depth_mm:g}` ({wall_s:.0f} s)",
             f"- Machine: {provenance.machine()}", f"- Date: {provenance.utc_now()} UTC",
             f"- Git revision: {provenance.git_revision()}", "",
             f"The tuned preset ({args.preset}) with its sample {args.width_mm:g} mm wide and its target "
             f"{args.depth_mm:g} mm deep (vertical), so that every angle's path and force meshes fit; the needle "
             "tilts towards +x on the line through the entry point (core/README.md, \"The needle at an angle\"). "
             "Not validated: the 3D FEM reference at an angle is so far a blunt flat punch, insertion only "
             "(no crack, friction or withdrawal; reference_fem/README.md), and the real-time model's "
             "tip is frictionless (the force mesh's load acts along the surface normal). What a reader can check: "
             "the needle at a and speed v presses the flat slab as the axial needle at v cos a does, so each "
             "break's vertical depth and normal load F_n equal that needle's (columns 'axial at v cos a'); the "
             "force across the needle is F_n sin a while only the tip's layer presses it (column 'across / "
             "(F sin a)', on the tick before the break, F the layer's load then); the force along the needle at "
             "the break is F_n cos a plus the cutting and friction behind the tip.", "",
             "## Punctures", "",
             "| angle | layer | depth mm | along the needle mm | normal load F_n N | axial at v cos a: depth mm, F_n N "
             "| force along the needle N | across, tick before N | across / (F sin a) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        a = math.radians(r["angle_deg"])
        lat, load = r["lateral_before_N"], r["layer_load_before_N"]
        lat_ratio = "n/a" if lat is None or r["angle_deg"] == 0 or not load else f"{lat / (load * math.sin(a)):.4f}"
        ref = "n/a" if r["axial_needle_depth_mm"] is None else \
            f"{r['axial_needle_depth_mm']:.3f}, {r['axial_needle_normal_load_N']:.3f}"
        lines.append(f"| {r['angle_deg']} | {r['layer']} | {r['depth_mm']:.3f} | {r['path_depth_mm']:.3f} | "
                     f"{r['normal_load_N']:.3f} | {ref} | {r['axial_force_N']:.3f} | "
                     f"{'n/a' if lat is None else f'{lat:.3f}'} | {lat_ratio} |")
    lines += ["", "## Peaks over the insertion", "",
              "| angle | peak along the needle N | at mm along the needle | peak across N "
              "| largest moment about the entry point N mm |",
              "|---|---|---|---|---|"]
    for angle, p in peak_rows.items():
        lines.append(f"| {angle} | {p['peak_axial_N']:.3f} | {p['peak_axial_path_mm']:.2f} | {p['peak_lateral_N']:.3f} "
                     f"| {p['peak_torque_N_mm']:.2f} |")
    lines += ["", "A peak at the target depth is the shaft's friction and damping (the inclined path puts 1 / cos a "
              "as much shaft in each layer)."]
    lines += ["", "![force along and across the needle against the depth along it](oblique_insertion.png)", "",
              "## Against measurements", "",
              "Schneider, Peck and Melvin 1978 (883 cadaver skin and muscle tests, via ../shared/LITERATURE.md "
              "[2nd]) found the puncture force insensitive to the angle. The frictionless tip gives the force along "
              "the needle at a break as F_n cos a: 3 % less at 15 deg, 13 % at 30, 29 % at 45. A tip that sticks "
              "to the surface would add a tangential spring and raise it; which is right is for the 3D reference "
              "and for recordings at an angle to decide (`validate --reference` takes them).", ""]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("preset")
    ap.add_argument("out_dir")
    ap.add_argument("binary")
    ap.add_argument("--width-mm", type=float, default=100.0)
    ap.add_argument("--depth-mm", type=float, default=25.0)
    args = ap.parse_args()
    with open(args.preset) as f:
        preset = json.load(f)
    start = time.time()
    rows, peak_rows, curves = [], {}, {}
    with tempfile.TemporaryDirectory() as work:
        for angle in ANGLES:
            print(f"[oblique] {angle} deg", flush=True)
            summary, curve = run_angle(args.binary, scene_at(preset, angle, args.width_mm, args.depth_mm), work)
            axial, _ = run_angle(args.binary, scene_at(preset, 0, args.width_mm, args.depth_mm,
                                                       math.cos(math.radians(angle)), f"axial_for_{angle}deg"), work)
            rows += break_rows(angle, summary, curve, axial)
            peak_rows[angle] = peaks(curve)
            curves[angle] = curve
    os.makedirs(args.out_dir, exist_ok=True)
    plot(curves, os.path.join(args.out_dir, "oblique_insertion.png"))
    header = list(rows[0].keys())
    csv_text = ",".join(header) + "\n" + "".join(
        ",".join("" if r[k] is None else str(r[k]) for k in header) + "\n" for r in rows)
    results_io.write_text(os.path.join(args.out_dir, "oblique_insertion.csv"), csv_text)
    results_io.write_text(os.path.join(args.out_dir, "README.md"), page(args, rows, peak_rows, time.time() - start))
    print(f"[oblique] wrote {args.out_dir}/README.md")


if __name__ == "__main__":
    main()
