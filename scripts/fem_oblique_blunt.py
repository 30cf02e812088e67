#!/usr/bin/python3
"""fem_oblique_blunt.py: the 3D FEM reference's blunt punch with the needle at an angle.

The default slab made a 3D blunt-tip scene (blunt_3d_scene.py: default materials and
needle radius, a flat tip, punctures at a needle force of 2 N), its sample widened to
WIDTH mm so that the steepest path's mesh stays valid (meshing/inclined_path_mesh.hpp)
and its target set to DEPTH mm (vertical), run by the FEM study driver at 0, 15, 30 and
45 deg (16 sectors, the default mesh) and at 30 deg on a finer cross-section (24
sectors): the mesh sensitivity at an angle. Per run: unknowns, wall time on this
machine, load steps and Newton iterations; where the force starts along the needle
against the closed form -a tan a (the square-cut face's lowest point); per puncture the
vertical depth, the depth along the needle, the force along and across the needle.
The plot: force along and across the needle against the depth along the needle.

What the numbers are: the 3D reference as it stands, a rigid flat punch moving along
the path, the tissue bonded to its face, a layer removed along the path when the force
reaches its threshold; no crack, friction, dwell or withdrawal (reference_fem/README.md).
Nothing here is a validation of the real-time model.

Usage: fem_oblique_blunt.py OUT_DIR [--study-bin build/reference_fem/puncture_fem_study]
                            [--width-mm 80] [--depth-mm 12] [--jobs 2]
Writes OUT_DIR/README.md, OUT_DIR/runs.csv, OUT_DIR/punctures.csv, OUT_DIR/force_path.png and
OUT_DIR/runs/<angle>deg_<sectors>sectors/ (each run's fem_force_depth.csv, fem_summary.json, scene.json).
"""
import argparse
import concurrent.futures
import json
import math
import os
import sys
import tempfile

import blunt_3d_scene
import provenance
import results_io
from fem_study_run import run_fem_study

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# (angle deg, sectors): the angles at 16 sectors, and 30 deg on the finer cross-section.
RUNS = ((0, 16), (15, 16), (30, 16), (45, 16), (30, 24))


def scene_at(angle, width_mm, depth_mm, work):
    """The blunt 3D default slab at ANGLE, written to the new folder WORK; returns (path, scene)."""
    os.makedirs(work)
    base = os.path.join(work, "blunt_3d.json")
    blunt_3d_scene.main(os.path.join(ROOT, "scenes", "default.json"), base)
    with open(base) as f:
        s = json.load(f)
    s["name"] = f"default_blunt_3d_{angle}deg"
    s["sample"]["diameter_mm"] = width_mm
    s["insertion"]["target_depth_mm"] = depth_mm
    s["insertion"]["angle_deg"] = float(angle)
    path = os.path.join(work, s["name"] + ".json")
    with open(path, "w") as f:
        json.dump(s, f, indent=1)
    return path, s



def path_depth(row):
    return float(row.get("path_depth_mm", row["depth_mm"]))


def lateral(row):
    return float(row.get("lateral_force_N", 0.0))


def first_contact(rows):
    """(path depth of the last row without force, of the first with force) in mm."""
    for prev, row in zip(rows, rows[1:]):
        if float(row["force_N"]) != 0.0:
            return path_depth(prev), path_depth(row)
    return None, None


def punctures(summary, rows):
    """Per puncture: layer, vertical depth, depth along the needle, axial and lateral force (the row before)."""
    out = []
    for p in summary.get("punctures", []):
        depth = p["depth_mm"]
        before = next((r for r in rows if abs(float(r["depth_mm"]) - depth) < 1e-6), None)
        out.append({"layer": p["name"], "depth_mm": depth,
                     "path_depth_mm": path_depth(before) if before else float("nan"),
                     "force_N": p["force_N"], "lateral_force_N": lateral(before) if before else float("nan")})
    return out


def plot(results, out_png):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 4.8))
    for (angle, sectors), r in results.items():
        if sectors != 16:
            continue
        x = [path_depth(row) for row in r["rows"]]
        line, = ax.plot(x, [float(row["force_N"]) for row in r["rows"]], label=f"{angle} deg, along the needle")
        if angle:
            ax.plot(x, [lateral(row) for row in r["rows"]], "--", color=line.get_color(),
                    label=f"{angle} deg, across the needle")
    ax.set_xlabel("tip depth along the needle (mm)")
    ax.set_ylabel("force on the needle (N)")
    ax.set_title("3D reference, blunt punch on the default slab at an angle (16 sectors)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    results_io.save_figure(fig, out_png)



def page(args, results, started):
    a = 0.635  # mm, the default needle radius (scenes/default.json)
    lines = ["# The 3D reference at an angle: the blunt punch", "",
             f"The default slab (skin 0.8 mm, fat 8.4 mm, muscle 39 mm; default materials) with a flat tip "
             f"(`scripts/blunt_3d_scene.py`: punctures at a needle force of 2 N), its sample {args.width_mm:g} mm "
             f"wide, inserted to {args.depth_mm:g} mm (vertical) at 0, 15, 30 and 45 deg by the 3D reference, whose "
             "needle column follows the inclined path (meshing/inclined_path_mesh.hpp). The reference is a rigid "
             "flat punch, square-cut, the tissue bonded to its face, a layer's column removed when the force along "
             "the needle reaches its threshold; no crack, friction, dwell or withdrawal (reference_fem/README.md). "
             "Nothing here validates the real-time model; the page shows what the 3D reference computes at an "
             "angle, what it costs, and how much a finer cross-section changes it.", "",
             "## Runs", "",
             "| angle (deg) | sectors | unknowns | wall (s) | load steps | Newton its | force starts along the needle (mm) | closed form -a tan a (mm) |",
             "|---|---|---|---|---|---|---|---|"]
    for (angle, sectors), r in results.items():
        lo, hi = r["first"]
        closed = -a * math.tan(math.radians(angle))
        lines.append(f"| {angle} | {sectors} | {r['summary']['n_dofs']} | {r['wall']:.0f} | {r['summary']['load_steps']} | "
                     f"{r['summary']['newton_iterations']} | {lo:.3f} to {hi:.3f} | {closed:.3f} |")
    lines += ["", "(The force starts between the last recorded row without force and the first with one; the face's "
              "lowest point meets the level surface at -a tan a along the needle, 0 along the sample axis; a "
              "load step is 0.2 mm vertical.)", "",
              "## Punctures", "",
              "| angle (deg) | sectors | layer | vertical depth (mm) | depth along the needle (mm) | along the needle (N) | across the needle (N) |",
              "|---|---|---|---|---|---|---|"]
    for (angle, sectors), r in results.items():
        for p in r["punctures"]:
            lines.append(f"| {angle} | {sectors} | {p['layer']} | {p['depth_mm']:.3f} | {p['path_depth_mm']:.3f} | "
                         f"{p['force_N']:.4f} | {p['lateral_force_N']:.4f} |")
    fine, coarse = results.get((30, 24)), results.get((30, 16))
    if fine and coarse:
        lines += ["", "## Mesh sensitivity at 30 deg (16 -> 24 sectors)", ""]
        for pc, pf in zip(coarse["punctures"], fine["punctures"]):
            lines.append(f"- {pc['layer']}: depth along the needle {pc['path_depth_mm']:.3f} -> {pf['path_depth_mm']:.3f} mm, "
                         f"force along the needle {pc['force_N']:.4f} -> {pf['force_N']:.4f} N "
                         f"({100 * (pf['force_N'] / pc['force_N'] - 1):+.1f} %), across "
                         f"{pc['lateral_force_N']:.4f} -> {pf['lateral_force_N']:.4f} N")
        if len(coarse["punctures"]) != len(fine["punctures"]):
            lines.append(f"- punctures: {len(coarse['punctures'])} with 16 sectors, {len(fine['punctures'])} with 24")
        lines.append("")
        lines.append("The 3D reference's refinement study along the axis (results/fem_mesh_convergence.md): Q1 without "
                     "refinement is about 10 % too stiff at small indentation; one refinement (8 times the unknowns) "
                     "was not run at an angle here.")
    lines += ["", "![force along and across the needle](force_path.png)", "",
              "Data: `runs.csv` (one row per run), `punctures.csv`; each run's force-depth CSV, summary and scene "
              "in `runs/`.", "",
              "## Provenance", "",
              f"- Command: `python3 scripts/fem_oblique_blunt.py {args.out} --study-bin {args.study_bin} "
              f"--width-mm {args.width_mm:g} --depth-mm {args.depth_mm:g} --jobs {args.jobs}` (wall times with "
              f"{args.jobs} run(s) side by side, each on one core)",
              f"- Machine: {provenance.machine()}", f"- Date: {started} to {provenance.utc_now()} UTC",
              f"- Git revision: {provenance.git_revision()}", ""]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("--study-bin", default="build/reference_fem/puncture_fem_study")
    ap.add_argument("--width-mm", type=float, default=80.0)
    ap.add_argument("--depth-mm", type=float, default=12.0)
    ap.add_argument("--jobs", type=int, default=2, help="runs side by side (each on one core)")
    args = ap.parse_args()
    if not os.path.exists(args.study_bin):
        sys.exit(f"fem_oblique_blunt: {args.study_bin}: no such program (build target puncture_fem_study)")
    started = provenance.utc_now()
    os.makedirs(args.out, exist_ok=True)
    results = {}
    with tempfile.TemporaryDirectory() as work:
        def one(key):
            angle, sectors = key
            scene_path, _ = scene_at(angle, args.width_mm, args.depth_mm, os.path.join(work, f"{angle}_{sectors}_scene"))
            return key, run_fem_study(args.study_bin, scene_path, os.path.join(work, f"{angle}_{sectors}"),
                                      os.path.join(args.out, "runs", f"{angle}deg_{sectors}sectors"), sectors=sectors)

        # The runs are serial programs (one rank): JOBS of them side by side.
        with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
            # the finer and steeper (longer) runs first
            for done, future in enumerate(concurrent.futures.as_completed([pool.submit(one, k) for k in reversed(RUNS)])):
                (angle, sectors), (wall, summary, rows) = future.result()
                results[(angle, sectors)] = {"wall": wall, "summary": summary, "rows": rows,
                                             "first": first_contact(rows), "punctures": punctures(summary, rows)}
                print(f"[{done + 1}/{len(RUNS)}] {angle} deg, {sectors} sectors: {wall:.0f} s, {summary['n_dofs']} "
                      f"unknowns, {len(results[(angle, sectors)]['punctures'])} punctures", flush=True)
    results = {k: results[k] for k in RUNS}
    results_io.write_csv_rows(os.path.join(args.out, "runs.csv"),
              [{"angle_deg": k[0], "sectors": k[1], "unknowns": r["summary"]["n_dofs"], "wall_s": round(r["wall"], 1),
                "load_steps": r["summary"]["load_steps"], "newton_iterations": r["summary"]["newton_iterations"],
                "first_force_path_depth_mm": r["first"][1], "closed_form_mm": -0.635 * math.tan(math.radians(k[0]))}
               for k, r in results.items()],
              ["angle_deg", "sectors", "unknowns", "wall_s", "load_steps", "newton_iterations",
               "first_force_path_depth_mm", "closed_form_mm"])
    results_io.write_csv_rows(os.path.join(args.out, "punctures.csv"),
              [dict(angle_deg=k[0], sectors=k[1], **p) for k, r in results.items() for p in r["punctures"]],
              ["angle_deg", "sectors", "layer", "depth_mm", "path_depth_mm", "force_N", "lateral_force_N"])
    plot(results, os.path.join(args.out, "force_path.png"))
    text = page(args, results, started)
    results_io.write_text(os.path.join(args.out, "README.md"), text)
    print(f"wrote {args.out}/README.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
