#!/usr/bin/env python3
"""comparison_cost.py: cost of one haptic step of every comparison model against
its resolution (issue 10, section 5), as a table, a log-log plot and the growth
order of each model (least-squares slope of log time against log DoFs).

Usage:
  scripts/comparison_cost.py [--bench BUILD/tests/benchmarks/bench_comparison_step]
                             [--out results/comparison_cost] [--report-only]
Runs the Google Benchmark program (tests/benchmarks/bench_comparison_step.cpp;
see its header for what one step and the resolutions are), keeps its JSON
(bench_comparison_step.json) and the volumetric models' integrator statistics
(integrator_report.txt), and writes comparison_cost.md and comparison_cost.png.
--report-only rewrites the markdown and the plot from the kept JSON.
The FEM rows (time per load step) are read from results/fem_axisymmetric_timing.md
(existing runs; no FEM is run here).

Run it niced on a shared machine: nice -n 19 scripts/comparison_cost.py
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys

import provenance  # scripts/provenance.py

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

KNOB = {
    "msm": "sample diameter (mesh grows with the skin disc)",
    "mass_tensor": "sample diameter (mesh grows with the skin disc)",
    "nonlinear_mass_tensor": "sample diameter (mesh grows with the skin disc)",
    "viscoelastic_mass_tensor": "sample diameter (mesh grows with the skin disc)",
    "bem": "annular elements on the needle disc",
    "shf": "SH degree l",
    "realtime": "SH degree l",
}
ORDER = ["realtime", "shf", "msm", "mass_tensor", "nonlinear_mass_tensor", "viscoelastic_mass_tensor", "bem", "fem"]


def fit_slope(xs, ys):
    """Least-squares slope of log y against log x (None if x does not vary)."""
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    n = len(lx)
    mx, my = sum(lx) / n, sum(ly) / n
    sxx = sum((a - mx) ** 2 for a in lx)
    if n < 2 or sxx < 1e-12:
        return None
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sxx


def fem_rows():
    """Time per load step of the axisymmetric FEM from results/fem_axisymmetric_timing.md (1-rank runs)."""
    path = os.path.join(ROOT, "results", "fem_axisymmetric_timing.md")
    rows = []
    if not os.path.exists(path):
        return rows
    for line in open(path):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 10 and cells[0] in ("1rank_1thread", "mesh_independence_default", "mesh_independence_fine"):
            dofs, steps, wall = int(cells[3]), int(cells[4]), float(cells[8])
            rows.append({"model": "fem", "resolution": cells[0], "dofs": dofs, "mean_us": 1e6 * wall / steps,
                         "cpu_us": None, "median_us": None, "memory_MB": None, "pressed": None})
    return rows


def parse_arguments():
    """Command line -> argparse namespace (bench, out, report_only, filter)."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bench", default=os.path.join(ROOT, "build", "tests", "benchmarks", "bench_comparison_step"))
    ap.add_argument("--out", default=os.path.join(ROOT, "results", "comparison_cost"))
    ap.add_argument("--report-only", action="store_true")
    ap.add_argument("--filter", default="", help="--benchmark_filter for a partial run")
    return ap.parse_args()


def run_benchmark(args, json_path, info_path, report_path):
    """Runs the benchmark program -> its JSON, integrator_report.txt and run_info.json (command, machine, load)."""
    cmd = [args.bench, "--benchmark_out_format=json", "--benchmark_out=" + json_path]
    if args.filter:
        cmd.append("--benchmark_filter=" + args.filter)
    info = {"command": "scripts/comparison_cost.py" + (f" --filter '{args.filter}'" if args.filter else ""),
            "machine": provenance.machine(), "started_utc": provenance.utc_now(),
            "git": provenance.git_revision(), "load_before": open("/proc/loadavg").read().split()[:3]}
    env = dict(os.environ, BENCH_COMPARISON_REPORT="1")
    with open(report_path, "w") as report:
        subprocess.run(cmd, check=True, env=env, stderr=report)
    info["finished_utc"] = provenance.utc_now()
    info["load_after"] = open("/proc/loadavg").read().split()[:3]
    json.dump(info, open(info_path, "w"), indent=1)


def benchmark_rows(data):
    """Benchmark JSON -> (one row per model step configuration, one row per CGAL mesh build)."""
    rows, meshes = [], []
    for b in data["benchmarks"]:
        parts = b["name"].split("/")
        if parts[0] == "BM_build_tet_mesh":
            meshes.append({"size": parts[1], "diameter": parts[2], "ms": b["real_time"],
                           **{k: b[k] for k in ("vertices", "tetrahedra", "vertices_in_skin", "vertices_on_side",
                                                "vertices_r_below_2a")}})
            continue
        if parts[0] != "BM_comparison_step":
            continue
        rows.append({"model": parts[1], "resolution": parts[2], "dofs": int(b["dofs"]), "nodes": int(b["nodes"]),
                     "mean_us": b["real_time"],
                     "cpu_us": b["cpu_time"], "median_us": b["step_median_us"], "memory_MB": b["memory_MB"],
                     "pressed": b["skin_pressed_fraction"]})
    return rows, meshes


def add_factorisations(rows, report_path):
    """Adds the factorisation count and s per factorisation of integrator_report.txt to the volumetric rows."""
    # Factorisations of the volumetric runs (integrator_report.txt, one line per
    # volumetric run, in the benchmark's order).
    reports = [l for l in open(report_path)] if os.path.exists(report_path) else []
    # "N sparse Cholesky factorisations (T s; ...)" (CHOLMOD, since 2026-12-02), "N sparse LDL^T
    # factorisations (T s)" in the reports of earlier runs.
    pattern = re.compile(r"^(\w+): .*?(\d+) sparse (?:LDL\^T|Cholesky) factorisations \(([0-9.eE+-]+) s[;)]")
    factorisations = [pattern.match(l) for l in reports]
    factorisations = [(m.group(1), int(m.group(2)), float(m.group(3))) for m in factorisations if m]
    volumetric = [x for x in rows if x["model"] in ("msm", "mass_tensor", "nonlinear_mass_tensor", "viscoelastic_mass_tensor")]
    for x, f in zip(volumetric, factorisations):
        if f[0] == x["model"] and f[1] > 0:
            x["factorisations"], x["s_per_factorisation"] = f[1], f[2] / f[1]


def growth_orders(rows):
    """Rows -> {model: (slope of the median, of the mean, of the mean CPU time) against DoFs, log-log}."""
    # Growth order per model: slope of log(median step time) against log(DoFs)
    # (the FEM: its mean time per load step).
    slopes = {}
    for m in ORDER:
        # Only windows that measured the same phase (skin pressed throughout).
        r = [x for x in rows if x["model"] == m and (x["pressed"] is None or x["pressed"] >= 0.99)]
        if len(r) < 2:
            continue
        t = [x["median_us"] if x["median_us"] is not None else x["mean_us"] for x in r]
        cpu = fit_slope([x["dofs"] for x in r], [x["cpu_us"] for x in r]) if all(x["cpu_us"] for x in r) else None
        slopes[m] = (fit_slope([x["dofs"] for x in r], t), fit_slope([x["dofs"] for x in r], [x["mean_us"] for x in r]), cpu)
    return slopes


def report_header(info):
    """run_info -> the page's title, provenance and what one step is, up to the step table's head."""
    return ["# Cost of one step of every comparison model against its resolution", "",
            f"Command: `nice -n 19 {info['command']}` (Google Benchmark program "
            "`tests/benchmarks/bench_comparison_step.cpp`, Release build), git "
            f"{info['git']}.  ",
            f"Machine: {info['machine']}; shared with other jobs while it ran (load average "
            f"{' '.join(info['load_before'])} before, {' '.join(info['load_after'])} after), so the times are upper bounds.  ",
            f"Date: {info['started_utc']} to {info['finished_utc']} UTC.", "",
            "What one step is: the default scene (`scenes/default.json`), a fresh model advanced untimed until the tip "
            "is 0.2 mm into the skin, then 100 haptic steps (1 kHz, 0.01 mm each, the skin pressed and unbroken: "
            "column `pressed`) timed one by one. `median` is the median single-step time over those 100 steps, `mean` "
            "their mean: the implicit volumetric models refactorise their Newton matrix on a few steps only, so their "
            "mean is many times their median. `mean CPU` is the benchmark thread's CPU time over the 100 steps / 100 "
            "(Google Benchmark's cpu_time): on a machine shared with other jobs it is far less inflated than the wall "
            "times, so the growth orders are also fitted to it. One run per configuration (the 100 steps are the sample). "
            "The FEM rows are not measured here: its wall time per accepted load step from "
            "`results/fem_axisymmetric_timing.md` (runs `1rank_1thread`, `mesh_independence_default`, "
            "`mesh_independence_fine`, one rank; the first is the whole default trajectory with 0.2 mm load steps, "
            "the other two the insertion to 14 mm; a mean, since the FEM records no per-step times).", ""]


def step_table(rows):
    """Rows -> the markdown table of the time per step of every model and resolution, by DoFs."""
    md = ["| model | resolution | DoFs | median per step (us) | mean per step (us) | mean CPU per step (us) | memory (MB) | pressed | factorisations in the run | s per factorisation |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    for m in ORDER:
        for x in sorted([x for x in rows if x["model"] == m], key=lambda x: x["dofs"]):
            md.append(f"| {m} | {x['resolution']} | {x['dofs']} | "
                      f"{'%.3g' % x['median_us'] if x['median_us'] is not None else 'n/a'} | {x['mean_us']:.3g} | "
                      f"{'%.3g' % x['cpu_us'] if x['cpu_us'] is not None else 'n/a'} | "
                      f"{'%.3g' % x['memory_MB'] if x['memory_MB'] is not None else 'n/a'} | "
                      f"{'%.2f' % x['pressed'] if x['pressed'] is not None else 'n/a'} | "
                      f"{x.get('factorisations', 'n/a')} | "
                      f"{'%.3g' % x['s_per_factorisation'] if 's_per_factorisation' in x else 'n/a'} |")
    return md


def growth_order_section(rows, slopes):
    """Rows and growth orders -> the growth-order table and the factorisation slopes, as markdown lines."""
    md = ["", "## Growth order (slope of log time against log DoFs, least squares)", "",
          "Fitted over the rows with `pressed` = 1 only (a window in which the skin broke measured another phase).", "",
          "| model | resolution knob | slope of the median | slope of the mean | slope of the mean CPU time |",
          "|---|---|---|---|---|"]
    for m in ORDER:
        if m not in slopes:
            continue
        s_med, s_mean, s_cpu = slopes[m]
        f = lambda s: "n/a (DoFs do not change)" if s is None else f"{s:.2f}"
        md.append(f"| {m} | {KNOB.get(m, 'FEM mesh (elements per needle radius)')} | {f(s_med)} | {f(s_mean)} | "
                  f"{'n/a' if m == 'fem' else f(s_cpu)} |")
    md += ["", "Volumetric models, one sparse factorisation of the Newton matrix (CHOLMOD's Cholesky, Eigen's LDL^T where it is not positive definite; wall time, from "
           "`integrator_report.txt`, every factorisation of the run; the matrix is 3 x nodes square for every law): slope of log(s per factorisation) against log(3 x nodes): " +
           ", ".join(f"{m} {fit_slope([3 * x['nodes'] for x in rows if x['model'] == m and 's_per_factorisation' in x], [x['s_per_factorisation'] for x in rows if x['model'] == m and 's_per_factorisation' in x]) or float('nan'):.2f}"
                     for m in ("msm", "mass_tensor", "nonlinear_mass_tensor", "viscoelastic_mass_tensor")
                     if len([x for x in rows if x['model'] == m and 's_per_factorisation' in x]) >= 2) + "."]
    return md


def mesh_table(meshes):
    """CGAL mesh rows -> the markdown section on the default slab's mesh (empty without mesh rows)."""
    md = []
    if meshes:
        md += ["", "## The CGAL mesh of the default slab (BM_build_tet_mesh)", "",
               "| size options | diameter | vertices | tetrahedra | vertices in the skin | on the side | within 2a of the axis | build (ms) |",
               "|---|---|---|---|---|---|---|---|"]
        for x in meshes:
            md.append(f"| {x['size']} | {x['diameter']} | {x['vertices']:.0f} | {x['tetrahedra']:.0f} | "
                      f"{x['vertices_in_skin']:.0f} | {x['vertices_on_side']:.0f} | {x['vertices_r_below_2a']:.0f} | "
                      f"{x['ms']:.0f} |")
    return md


def report_markdown(info, rows, meshes, slopes):
    """run_info, rows, mesh rows and growth orders -> the text of comparison_cost.md."""
    md = report_header(info) + step_table(rows) + growth_order_section(rows, slopes) + mesh_table(meshes)
    md += ["", "Integrator statistics of each volumetric run (whole run from t = 0, incl. the untimed approach): "
           "`integrator_report.txt`. Raw benchmark output: `bench_comparison_step.json`.", "",
           "![comparison_cost.png](comparison_cost.png)", ""]
    return "\n".join(md)


def plot_cost(path, info, rows, slopes):
    """Rows and growth orders -> the log-log plot of the time per step against DoFs, written to path."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5.5))
    for m in ORDER:
        r = sorted([x for x in rows if x["model"] == m], key=lambda x: x["dofs"])
        if not r:
            continue
        t = [(x["median_us"] if x["median_us"] is not None else x["mean_us"]) * 1e-6 for x in r]
        label = m
        if m in slopes and slopes[m][0] is not None:
            label += f" (slope {slopes[m][0]:.2f})"
        line, = ax.loglog([x["dofs"] for x in r], t, "o-", label=label)
        if m not in ("fem",) and all(x["median_us"] is not None for x in r):
            ax.loglog([x["dofs"] for x in r], [x["mean_us"] * 1e-6 for x in r], "x:", color=line.get_color())
    ax.axhline(1e-3, color="gray", lw=0.8, ls="--")
    ax.text(ax.get_xlim()[0] * 1.1, 1.15e-3, "1 ms haptic step", color="gray", fontsize=8)
    ax.set_xlabel("DoFs (state size of the model)")
    ax.set_ylabel("time per step (s): median (o, solid), mean (x, dotted)")
    ax.set_title("One step of each comparison model (default scene, skin pressed); FEM: per load step", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)
    fig.text(0.01, 0.005, f"{info['command']}, git {info['git']}, {info['machine']}, {info['started_utc']} UTC",
             fontsize=5.5)
    fig.tight_layout(rect=(0, 0.02, 1, 1))
    fig.savefig(path, dpi=130)


def main():
    """Command line -> (a benchmark run unless --report-only, then) comparison_cost.md and comparison_cost.png in OUT."""
    args = parse_arguments()
    os.makedirs(args.out, exist_ok=True)
    json_path = os.path.join(args.out, "bench_comparison_step.json")
    info_path = os.path.join(args.out, "run_info.json")
    report_path = os.path.join(args.out, "integrator_report.txt")
    if not args.report_only:
        run_benchmark(args, json_path, info_path, report_path)
    info = json.load(open(info_path))
    data = json.load(open(json_path))
    rows, meshes = benchmark_rows(data)
    add_factorisations(rows, report_path)
    rows += fem_rows()
    slopes = growth_orders(rows)
    open(os.path.join(args.out, "comparison_cost.md"), "w").write(report_markdown(info, rows, meshes, slopes))
    plot_cost(os.path.join(args.out, "comparison_cost.png"), info, rows, slopes)
    print("wrote", os.path.join(args.out, "comparison_cost.md"))


if __name__ == "__main__":
    sys.exit(main())
