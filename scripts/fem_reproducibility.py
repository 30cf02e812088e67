#!/usr/bin/env python3
"""fem_reproducibility.py: is the FEM reference the same answer on another BLAS
and at another target depth?

Runs `puncture fem` (one assembly thread each, two runs side by side) on
  * each scene of SCENES under Debian's reference BLAS and under OpenBLAS
    (the same binary, OpenBLAS's libblas/liblapack put first on
    LD_LIBRARY_PATH; OPENBLAS_NUM_THREADS=1), and
  * the default slab to 20 mm and to 30 mm (the default target),
and compares each pair: every puncture's depth and force, and the force RMSE
of the whole curve (the second run interpolated in time at the first's rows;
for the two targets, the insertion to 20 mm that both share), relative to the
first run's peak force. Writes results/fem_reproducibility/README.md and
comparison.csv; exit status 1 if any difference exceeds 1 %.

  python3 scripts/fem_reproducibility.py [--build build] [--out results/fem_reproducibility]
"""
import argparse
import concurrent.futures
import json
import math
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fem_robustness as fr  # noqa: E402
import provenance  # noqa: E402
import results_io  # noqa: E402

ROOT = fr.ROOT
SCENES = ["scenes/default.json", "tests/reference_fem/scenes/thick_skin_soft_fat.json",
          "tests/reference_fem/scenes/tough_skin_slow.json", "tests/reference_fem/scenes/deep_fat_stall.json"]
OPENBLAS_PACKAGE = "libopenblas0-serial"
OPENBLAS_DIRS = ["/usr/lib/x86_64-linux-gnu/openblas-serial", "/usr/lib/aarch64-linux-gnu/openblas-serial"]
TOLERANCE = 0.01


BLAS_ALTERNATIVES = ["libblas.so.3-x86_64-linux-gnu", "liblapack.so.3-x86_64-linux-gnu",
                     "libblas.so.3-aarch64-linux-gnu", "liblapack.so.3-aarch64-linux-gnu"]


def alternative_selections():
    """Debian's BLAS and LAPACK alternatives as the machine selects them now: name -> library path."""
    selected = {}
    for name in BLAS_ALTERNATIVES:
        q = subprocess.run(["update-alternatives", "--query", name], capture_output=True, text=True, check=False)
        for line in q.stdout.splitlines():
            if line.startswith("Value: "):
                selected[name] = line[len("Value: "):].strip()
    return selected


def openblas_dir():
    """The serial OpenBLAS's folder, installed if missing (Debian's package;
    the runs put it first on LD_LIBRARY_PATH, whatever BLAS the machine
    selects). Installing it makes Debian's alternatives select it for every
    program; the machine's selection is put back, as the serial OpenBLAS is
    not safe to call from two threads of one process (results/comparison/README.md)."""
    for attempt in range(2):
        for d in OPENBLAS_DIRS:
            if os.path.exists(os.path.join(d, "libblas.so.3")):
                return d
        if attempt == 0:
            sudo = [] if os.geteuid() == 0 else ["sudo"]
            before = alternative_selections()
            print(f"fem_reproducibility: installing {OPENBLAS_PACKAGE}", flush=True)
            subprocess.run(sudo + ["apt-get", "install", "-y", "-qq", "--no-install-recommends", OPENBLAS_PACKAGE],
                           env=dict(os.environ, DEBIAN_FRONTEND="noninteractive"), check=False)
            for name, path in before.items():
                if alternative_selections().get(name) != path:
                    print(f"fem_reproducibility: {name} back to {path}", flush=True)
                    subprocess.run(sudo + ["update-alternatives", "--set", name, path], check=False)
    sys.exit(f"fem_reproducibility: OpenBLAS is not installed (apt-get install {OPENBLAS_PACKAGE})")


REFERENCE_DIRS = ["/usr/lib/x86_64-linux-gnu/blas", "/usr/lib/aarch64-linux-gnu/blas"]


def reference_dir():
    for d in REFERENCE_DIRS:
        if os.path.exists(os.path.join(d, "libblas.so.3")):
            return d
    sys.exit("fem_reproducibility: Debian's reference BLAS (libblas3) is not installed")


def run(binary, scene, out, blas_dir):
    env = dict(os.environ, PUNCTURE_FEM_THREADS="1")
    lapack_dir = blas_dir.replace("/blas", "/lapack") if blas_dir.endswith("/blas") else blas_dir
    env["LD_LIBRARY_PATH"] = ":".join([blas_dir, lapack_dir] + ([env["LD_LIBRARY_PATH"]] if env.get("LD_LIBRARY_PATH") else []))
    t0 = time.monotonic()
    p = subprocess.run([binary, "fem", scene, "-o", out, "--no-vtu", "-q"], env=env, stdout=subprocess.PIPE,
                       stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{scene} ({blas_dir}): {p.stderr.strip()}")
    with open(os.path.join(out, "fem_summary.json")) as f:
        summary = json.load(f)
    rows = fr.read_force_depth(os.path.join(out, "fem_force_depth.csv"))
    return {"summary": summary, "rows": rows, "wall_s": time.monotonic() - t0}


def interpolate(ts, fs, t):
    if t <= ts[0]:
        return fs[0]
    for k in range(1, len(ts)):
        if ts[k] >= t:
            w = (t - ts[k - 1]) / (ts[k] - ts[k - 1]) if ts[k] > ts[k - 1] else 1.0
            return fs[k - 1] + w * (fs[k] - fs[k - 1])
    return fs[-1]


def compare(a, b, until_depth_mm=None):
    """Relative differences of b from a: per puncture (depth, force) and the curve's RMSE / peak."""
    pa, pb = a["summary"]["punctures"], b["summary"]["punctures"]
    peak = max(float(r["force_N"]) for r in a["rows"])
    rows_a = a["rows"]
    if until_depth_mm is not None:
        rows_a = [r for r in rows_a if r["phase"] in ("approach", "insertion") and float(r["depth_mm"]) <= until_depth_mm + 1e-9]
    tb = [float(r["time_s"]) for r in b["rows"]]
    fb = [float(r["force_N"]) for r in b["rows"]]
    sq = [(float(r["force_N"]) - interpolate(tb, fb, float(r["time_s"]))) ** 2 for r in rows_a]
    rmse = math.sqrt(sum(sq) / len(sq)) / peak
    events = []
    names_b = {e["name"]: e for e in pb}
    for e in pa:
        if until_depth_mm is not None and e["depth_mm"] > until_depth_mm:
            continue
        o = names_b.get(e["name"])
        if o is None:
            events.append((e["name"], e["depth_mm"], float("nan"), e["force_N"], float("nan")))
        else:
            events.append((e["name"], e["depth_mm"], o["depth_mm"], e["force_N"], o["force_N"]))
    return rmse, events


def worst(rmse, events):
    w = rmse
    for _, da, db, fa, fb in events:
        if math.isnan(db):
            return float("inf")
        w = max(w, abs(db - da) / da, abs(fb - fa) / fa)
    return w


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.environ.get("PUNCTURE_BUILD_DIR", os.path.join(ROOT, "build")))
    ap.add_argument("--out", default=os.path.join(ROOT, "results", "fem_reproducibility"))
    ap.add_argument("--jobs", type=int, default=2)
    args = ap.parse_args()
    binary = os.path.join(args.build, "apps", "puncture")
    ob, ref = openblas_dir(), reference_dir()
    work = tempfile.mkdtemp(prefix="fem_repro_")
    with open(os.path.join(ROOT, "scenes", "default.json")) as f:
        d20 = json.load(f)
    d20["name"] = "default_to_20_mm"
    d20["insertion"]["target_depth_mm"] = 20.0
    d20_path = os.path.join(work, "default_to_20_mm.json")
    fr.write_scene(d20, d20_path)
    jobs = {}
    for s in SCENES:
        name = os.path.splitext(os.path.basename(s))[0]
        jobs[(name, "reference")] = (os.path.join(ROOT, s), ref)
        jobs[(name, "openblas")] = (os.path.join(ROOT, s), ob)
    jobs[("default_to_20_mm", "reference")] = (d20_path, ref)
    results = {}
    t0 = time.monotonic()
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        futures = {pool.submit(run, binary, scene, os.path.join(work, f"{k[0]}_{k[1]}"), blas): k
                   for k, (scene, blas) in jobs.items()}
        for f in concurrent.futures.as_completed(futures):
            k = futures[f]
            results[k] = f.result()
            print(f"[{time.monotonic() - t0:.0f} s] {k[0]} ({k[1]}): {results[k]['wall_s']:.0f} s", flush=True)
    lines = ["# The FEM reference on another BLAS and at another target depth", "",
             f"Made by `python3 scripts/fem_reproducibility.py` on {provenance.machine()} "
             f"(OpenBLAS runs: {ob}, one thread), {provenance.utc_now()} UTC, git {provenance.git_revision()}.",
             "Each pair: the same binary; differences relative to the first run (puncture depth and force; "
             "force RMSE of the curve over the first run's peak force). Acceptance: every difference within "
             f"{TOLERANCE:.0%}.", "",
             "| pair | layer | depth mm | depth mm (2nd) | force N | force N (2nd) | |", "|---|---|---|---|---|---|---|"]
    csv = ["pair,layer,depth_mm,depth2_mm,force_N,force2_N,curve_rmse_over_peak,worst_relative_difference"]
    summary_rows = []
    pairs = [(f"{os.path.splitext(os.path.basename(s))[0]}: reference BLAS / OpenBLAS",
              results[(os.path.splitext(os.path.basename(s))[0], "reference")],
              results[(os.path.splitext(os.path.basename(s))[0], "openblas")], None) for s in SCENES]
    pairs.append(("default: to 30 mm / to 20 mm (insertion to 20 mm)", results[("default", "reference")],
                  results[("default_to_20_mm", "reference")], 20.0))
    ok = True
    for label, a, b, until in pairs:
        rmse, events = compare(a, b, until)
        w = worst(rmse, events)
        ok = ok and w <= TOLERANCE
        for name, da, db, fa, fb in events:
            lines.append(f"| {label} | {name} | {da:.3f} | {db:.3f} | {fa:.4f} | {fb:.4f} | |")
            csv.append(f"{label},{name},{da:.6g},{db:.6g},{fa:.6g},{fb:.6g},{rmse:.4g},{w:.4g}")
        summary_rows.append(f"| {label} | {rmse:.2e} | {w:.2e} | {'yes' if w <= TOLERANCE else '**no**'} |")
    lines += ["", "| pair | curve RMSE / peak | worst difference | within 1 % |", "|---|---|---|---|"] + summary_rows
    lines += ["", f"Wall times (s, one thread, two runs side by side): " +
              ", ".join(f"{k[0]} {k[1]} {v['wall_s']:.0f}" for k, v in sorted(results.items())), ""]
    os.makedirs(args.out, exist_ok=True)
    results_io.write_text(os.path.join(args.out, "README.md"), "\n".join(lines))
    results_io.write_text(os.path.join(args.out, "comparison.csv"), "\n".join(csv) + "\n")
    print(f"fem_reproducibility: {'all within' if ok else 'NOT all within'} {TOLERANCE:.0%}; {args.out}/README.md")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
