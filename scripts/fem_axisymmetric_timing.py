#!/usr/bin/env python3
"""fem_axisymmetric_timing.py: where the axisymmetric FEM reference spends its time.

Reads FEM runs that already exist (each a directory with fem_summary.json and
fem_newton_log.txt, e.g. the default scene's reference made by
scripts/results_validation.sh or by `puncture fem`, and the runs of
scripts/fem_puncture_mesh_independence.sh and
scripts/fem_axisymmetric_convergence.sh) and writes two tables:
  1. per run: mesh, DoFs, load steps, step cuts, Newton iterations, wall time,
     time per Newton iteration;
  2. per run, from its Newton log: where the iterations went (converged steps,
     attempts given up and cut, steps accepted at a stall) and the median
     time of one tangent assembly and one sparse direct solve.
A run given as LABEL=DIR is shown under LABEL (e.g. the same scene before and
after a solver change); runs given under one label more than once are repeats
of one run (e.g. by scripts/fem_timing_ab.sh): one row, the median wall time
and each run's. The table says nothing about a run it was not given.
Each --note TEXT is printed under the tables as given (what a run changed).

Usage: scripts/fem_axisymmetric_timing.py OUT_MD [--note TEXT]... [LABEL=]RUN_DIR...
"""
import json
import os
import re
import statistics
import sys

import provenance  # scripts/provenance.py (the script's own folder is on sys.path)


def newton_stats(log_path):
    """Iterations in converged steps and in failed attempts, stall acceptances,
    median assembly and solve times (s) of one iteration."""
    s = {"converged_steps": 0, "converged_its": 0, "failed_attempts": 0, "failed_its": 0, "stall_accepted": 0,
         "t_assemble": [], "t_solve": []}
    if not os.path.exists(log_path):
        return None
    its = 0
    for line in open(log_path):
        if line.startswith("step "):
            its = 0
            continue
        m = re.search(r"t_assemble ([0-9.e+-]+) s\s+t_solve ([0-9.e+-]+) s", line)
        if m:
            its += 1
            s["t_assemble"].append(float(m.group(1)))
            s["t_solve"].append(float(m.group(2)))
        if "converged" in line and "|R_free|" in line:
            s["converged_steps"] += 1
            s["converged_its"] += its
            if "stalled below" in line:
                s["stall_accepted"] += 1
            its = 0
        elif line.strip().startswith("->"):
            s["failed_attempts"] += 1
            s["failed_its"] += its
            its = 0
    return s


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    out, rest = sys.argv[1], sys.argv[2:]
    notes, args = [], []
    while rest:
        a = rest.pop(0)
        if a == "--note" and rest:
            notes.append(rest.pop(0))
        else:
            args.append(a)
    runs = {}  # label (or the directory) -> its run directories, in the order given
    for a in args:
        label, path = a.split("=", 1) if "=" in a and not os.path.exists(a) else (None, a)
        if os.path.isfile(path):
            path = os.path.dirname(path)
        runs.setdefault(label or path, []).append((label, path))
    rev = provenance.git_revision()
    L = ["# Axisymmetric FEM: time per run, per load step and per Newton iteration\n",
         f"Command: `scripts/fem_axisymmetric_timing.py {out} "
         f"{' '.join((['--note TEXT'] * len(notes)) + args)}` (the TEXTs: the notes at the end, in order), "
         f"git {rev}.  ",
         f"Machine: {provenance.machine()}; the runs were made on this "
         "shared machine, some while other builds and tests ran, so the wall times are upper bounds.  ",
         f"Date: {provenance.utc_now()} UTC.\n",
         "## Runs\n",
         "| run | element | cells | DoFs | load steps | step cuts | Newton iterations | per step | "
         "wall (s) | s per Newton iteration |",
         "|---|---|---|---|---|---|---|---|---|---|"]
    stats = []
    for group in runs.values():
        label, path = group[0]
        j = json.load(open(os.path.join(path, "fem_summary.json")))
        steps = j.get("load_steps", 0)
        its = j.get("newton_iterations", 0)
        walls = [json.load(open(os.path.join(p, "fem_summary.json"))).get("wall_time_s", float("nan"))
                 for _, p in group]
        wall = statistics.median(walls)
        wall_text = f"{wall:.0f}" if len(walls) == 1 else \
            f"{wall:.1f} (median of {len(walls)}: {', '.join(f'{w:.1f}' for w in walls)})"
        name = label or j.get("scene", os.path.basename(path))
        L.append(f"| {name} | Q{j.get('element_degree', 1)} | "
                 f"{j.get('n_cells', '')} | {j.get('n_dofs', '')} | {steps} | "
                 f"{j.get('step_cuts', '')} | {its} | {its / steps if steps else float('nan'):.1f} | {wall_text} | "
                 f"{wall / its if its else float('nan'):.3f} |")
        stats.append((name, newton_stats(os.path.join(path, "fem_newton_log.txt"))))
    L += ["", "## Where the Newton iterations and their time go (from each run's fem_newton_log.txt)\n",
          "| run | converged steps | iterations per converged step | attempts cut | iterations in cut attempts | "
          "steps accepted at a stall | median assembly (s) | median UMFPACK factor+solve (s) |",
          "|---|---|---|---|---|---|---|---|"]
    for name, s in stats:
        if s is None:
            L.append(f"| {name} | (no Newton log) | | | | | | |")
            continue
        per = s["converged_its"] / s["converged_steps"] if s["converged_steps"] else float("nan")
        ta = statistics.median(s["t_assemble"]) if s["t_assemble"] else float("nan")
        ts = statistics.median(s["t_solve"]) if s["t_solve"] else float("nan")
        L.append(f"| {name} | {s['converged_steps']} | {per:.1f} | {s['failed_attempts']} | {s['failed_its']} | "
                 f"{s['stall_accepted']} | {ta:.4f} | {ts:.4f} |")
    L += ["",
          "Each Newton iteration assembles the tangent (finite-strain three-field cells, cohesive points, contact "
          "and friction nodes), solves it with UMFPACK (nonsymmetric because of friction) and line-searches on "
          "the residual (from 8b34964 the full step is assembled with its tangent, which the next iteration takes "
          "over when the step is accepted; the shorter trials are residual-only assemblies). Iterations per converged step measure the tangent's "
          "consistency; iterations in cut attempts measure the work thrown away where Newton fails (the skin's "
          "snap-through, kinks of contact and full damage) before the step is cut; the median assembly and "
          "solve times measure the cost of one iteration."]
    if notes:
        L += ["", "## Notes on the runs\n"] + [f"- {n}" for n in notes]
    tmp = out + ".part"
    open(tmp, "w").write("\n".join(L) + "\n")
    os.replace(tmp, out)
    print("wrote", out)


if __name__ == "__main__":
    main()
