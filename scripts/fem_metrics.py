"""fem_metrics.py: numbers a reader compares with measurements, from one FEM
output folder (fem_summary.json, fem_force_depth.csv of `puncture fem`).

read_fem(dir)            -> (summary dict, rows: list of dicts of the CSV)
value(row, key)          -> float of one column
friction_per_mm(s, rows) -> (slope N/mm, first depth mm, last depth mm, n) of
                            the friction column against depth from 1 mm below
                            the last puncture to the target (the shaft then
                            slides through every punctured layer); None if
                            fewer than 3 steps
dwell_relaxation(rows)   -> (force at the start of the hold N, at its end N,
                            hold s, relaxed fraction end/start); None without
                            a dwell
"""
import csv
import json
import os


def read_fem(fem_dir):
    summary = json.load(open(os.path.join(fem_dir, "fem_summary.json")))
    with open(os.path.join(fem_dir, "fem_force_depth.csv"), newline="") as f:
        rows = list(csv.DictReader(l for l in f if not l.startswith("#")))
    if not rows:
        raise SystemExit(f"{fem_dir}/fem_force_depth.csv: no rows")
    return summary, rows


def value(row, key):
    return float(row[key])


def least_squares_slope(points):
    n = len(points)
    mx = sum(x for x, _ in points) / n
    my = sum(y for _, y in points) / n
    return sum((x - mx) * (y - my) for x, y in points) / sum((x - mx) ** 2 for x, _ in points)


def friction_per_mm(summary, rows):
    punctures = summary.get("punctures", [])
    if not punctures:
        return None
    z0 = max(p["depth_mm"] for p in punctures) + 1.0
    pts = [(value(r, "depth_mm"), value(r, "friction_force_N")) for r in rows
           if r["phase"] == "insertion" and value(r, "depth_mm") >= z0]
    if len(pts) < 3:
        return None
    return least_squares_slope(pts), pts[0][0], pts[-1][0], len(pts)


def dwell_relaxation(rows):
    ins = [r for r in rows if r["phase"] == "insertion"]
    dwell = [r for r in rows if r["phase"] == "dwell"]
    if not ins or not dwell:
        return None
    f0, f1 = value(ins[-1], "force_N"), value(dwell[-1], "force_N")
    hold = value(dwell[-1], "time_s") - value(ins[-1], "time_s")
    return f0, f1, hold, (f1 / f0 if f0 > 0 else float("nan"))
