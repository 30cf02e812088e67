#!/usr/bin/env python3
"""fem_axisymmetric_timing.py: where the axisymmetric FEM reference spends its time.

Reads the fem_summary.json of FEM runs that already exist (the default
scene's cached reference made by scripts/results_validation.sh, the runs of
scripts/fem_puncture_mesh_independence.sh and
scripts/fem_axisymmetric_convergence.sh) and writes a table: mesh, DoFs, load
steps, step cuts, Newton iterations, wall time, time per Newton iteration.
The runs were timed as they were made (see each run's date in the table's
source summaries); the machine may have been loaded.

Usage: scripts/fem_axisymmetric_timing.py OUT_MD SUMMARY_JSON...
"""
import datetime
import json
import os
import platform
import subprocess
import sys


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out, paths = sys.argv[1], sys.argv[2:]
    rev = "unknown"
    try:
        rev = subprocess.check_output(["git", "-C", os.path.dirname(os.path.abspath(__file__)), "rev-parse", "--short",
                                       "HEAD"], text=True).strip()
    except Exception:
        pass
    cpu = "unknown"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    L = ["# Axisymmetric FEM: time per run, per load step and per Newton iteration\n",
         f"Command: `scripts/fem_axisymmetric_timing.py {out} {' '.join(os.path.relpath(p) for p in paths)}`, git {rev}.  ",
         f"Machine: {platform.system()} {platform.release()}, {os.cpu_count()} cores ({cpu}); the runs were made on this "
         "shared machine while other builds and tests ran, so the wall times are upper bounds.  ",
         f"Date: {datetime.datetime.utcnow().strftime('%Y-%m-%d %H:%M')} UTC.\n",
         "| run | element | cells | DoFs | load steps | step cuts | Newton iterations | per step | "
         "wall (s) | s per Newton iteration |",
         "|---|---|---|---|---|---|---|---|---|---|"]
    for p in paths:
        j = json.load(open(p))
        steps = j.get("load_steps", 0)
        its = j.get("newton_iterations", 0)
        wall = j.get("wall_time_s", float("nan"))
        L.append(f"| {j.get('scene', os.path.basename(os.path.dirname(p)))} | Q{j.get('element_degree', 1)} | "
                 f"{j.get('n_cells', '')} | {j.get('n_dofs', '')} | {steps} | "
                 f"{j.get('step_cuts', '')} | {its} | {its / steps if steps else float('nan'):.1f} | {wall:.0f} | "
                 f"{wall / its if its else float('nan'):.3f} |")
    L.append("")
    L.append("Each Newton iteration assembles the tangent (finite-strain three-field cells, cohesive points, contact "
             "and friction nodes) and solves it with UMFPACK (nonsymmetric because of friction). The default run "
             "needs about 14 iterations per load step: the regularised friction and the crack's softening make "
             "convergence slow near the punctures; that, not the linear solver, is what keeps the full default "
             "insertion above the 3 minute aim.")
    tmp = out + ".part"
    open(tmp, "w").write("\n".join(L) + "\n")
    os.replace(tmp, out)
    print("wrote", out)


if __name__ == "__main__":
    main()
