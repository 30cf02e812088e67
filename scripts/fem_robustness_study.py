#!/usr/bin/env python3
"""fem_robustness_study.py: the FEM reference on scenes drawn at random.

Draws COUNT scenes with a seeded generator (scripts/fem_robustness.py: each
layer's thickness, modulus, stiffening, Prony terms, toughness, cohesive
strength and friction, speed 1-20 mm/s, target depth over the whole slab,
hold 0-10 s, bevel and blunt tips), runs `puncture fem` on each, JOBS scenes
side by side (one assembly thread each), checks every run's outputs with
fem_robustness.check_run (independently of the solver's own flags) and writes
OUT/README.md (the page), OUT/runs.csv (one row per scene), OUT/scenes/ (every
drawn scene, so any row can be run again by hand), OUT/results/ (each scene's
record) and OUT/runs/ (each run's outputs; not committed).

  python3 scripts/fem_robustness_study.py [--count 60] [--seed 48] [--jobs 2]
          [--family full|small] [--out results/fem_robustness] [--build build]
  # one scene only (a cluster task; OUT/runs/<name>/ and OUT/results/<name>.json):
  python3 scripts/fem_robustness_study.py --only 17 --out DIR
  # the page from the per-scene results already in OUT (after the tasks):
  python3 scripts/fem_robustness_study.py --collect --out DIR
  # go on with a study stopped part way: scenes with a result from the same
  # FEM sources are kept (the digest of the sources their geometry's run
  # executes, scripts/fem_source_digest.py; comments do not count):
  python3 scripts/fem_robustness_study.py --resume
  # a page from the results so far, the scenes not yet run with the current
  # FEM sources listed as such:
  python3 scripts/fem_robustness_study.py --collect --partial

Exit status: 0 when every scene converged with consistent records, 1 otherwise.
"""
import argparse
import concurrent.futures
import json
import os
import random
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fem_robustness as fr  # noqa: E402
import fem_source_digest as fsd  # noqa: E402
import provenance  # noqa: E402
import results_io  # noqa: E402


def scenes_of(count, seed, family):
    rng = random.Random(seed)
    return [fr.draw_scene(rng, family, i) for i in range(count)]


def current_fem_sources(binary):
    """The program's git revision and, per FEM geometry, the digest of the sources its runs execute
    (scripts/fem_source_digest.py). The program must be built from the FEM sources of this tree."""
    revision, program_digest = fsd.program_version(binary)
    if program_digest != fsd.digest():
        sys.exit(f"fem_robustness_study: {binary} was built from other FEM sources ({program_digest}) than "
                 f"this tree's ({fsd.digest()}): rebuild it (bash scripts/build.sh) or pass --build of a current build")
    return revision, {g: fsd.digest(None, g) for g in fsd.GEOMETRIES}


def record_digest(rec, scene):
    """The digest of the FEM sources a record's run executed: its own field, or, for a record made
    before records carried it, computed from the git revision it names (None if unknown)."""
    if rec.get("fem_digest"):
        return rec["fem_digest"]
    revision = rec.get("fem_source", "unknown")
    if revision == "unknown" or revision.endswith("-dirty"):
        return None
    try:
        return fsd.digest(revision, fsd.scene_geometry(scene))
    except (subprocess.CalledProcessError, OSError):
        return None


def current_record(out, scene, digests):
    """OUT's record of SCENE when its run executed the current FEM sources of the scene's geometry, else None."""
    rec = existing_result(out, scene["name"])
    if rec is None:
        return None
    geometry, digest = fsd.scene_geometry(scene), record_digest(rec, scene)
    if not fsd.same_runs(geometry, digest, digests[geometry]):
        return None
    rec.setdefault("fem_digest", digest)
    rec.setdefault("geometry", geometry)
    return rec


def run_one(scene, out, binary, threads, sources):
    """Runs the FEM on one scene; returns (and writes) its result record."""
    name, geometry = scene["name"], fsd.scene_geometry(scene)
    scene_path = os.path.join(out, "scenes", name + ".json")
    run_dir = os.path.join(out, "runs", name)
    shutil.rmtree(run_dir, ignore_errors=True)
    env = dict(os.environ, PUNCTURE_FEM_THREADS=str(threads))
    t0 = time.monotonic()
    p = subprocess.run([binary, "fem", scene_path, "-o", run_dir, "--no-vtu", "-q"], env=env,
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wall = time.monotonic() - t0
    rec = {"scene": name, "exit": p.returncode, "wall_s": round(wall, 1), "error": "", "problems": [],
           "tip": scene["needle"]["tip"], "target_mm": scene["insertion"]["target_depth_mm"],
           "speed_mm_per_s": scene["insertion"]["speed_mm_per_s"], "hold_s": scene["insertion"]["dwell_s"],
           "thickness_mm": [l["thickness_mm"] for l in scene["layers"]], "fem_source": sources[0],
           "geometry": geometry, "fem_digest": sources[1][geometry],
           "finished_utc": provenance.utc_now()}
    if p.returncode != 0:
        lines = [l for l in p.stderr.splitlines() if l.strip() and not l.startswith("warning")]
        rec["error"] = lines[-1] if lines else f"exit {p.returncode}"
    else:
        with open(os.path.join(run_dir, "fem_summary.json")) as f:
            s = json.load(f)
        rec.update({"load_steps": s.get("load_steps"), "step_cuts": s.get("step_cuts"),
                    "accepted_at_stall": s.get("steps_accepted_at_stall"), "continued": s.get("steps_continued"),
                    "newton_iterations": s.get("newton_iterations"), "status": s.get("status"),
                    "last_resort": s.get("steps_accepted_last_resort", 0),
                    "largest_residual_share": (s.get("largest_accepted_residual_N", 0.0) /
                                               max(s.get("peak_force_N") or 0.0, 1e-300)),
                    "punctures": [(e["name"], round(e["depth_mm"], 3), round(e["force_N"], 4))
                                  for e in s.get("punctures", [])]})
        rec["problems"] = fr.check_run(run_dir)
        rec["crack_released_share"] = released_share(out, name)
    results_io.write_text(os.path.join(out, "results", name + ".json"), json.dumps(rec, indent=1))
    return rec


def existing_result(out, name):
    """The record OUT/results/<name>.json, or None."""
    path = os.path.join(out, "results", name + ".json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        return json.load(f)


def median(v):
    v = sorted(v)
    n = len(v)
    return float("nan") if n == 0 else (v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2]))


def released_share(out, scene, rec=None):
    """The share of a run's crack dissipation that came from energy the
    tissue had stored (crack_energy_released_J / cohesive_dissipation_J of
    OUT/runs/<scene>/fem_summary.json; the record REC keeps it, since the
    run directories are not committed), or None."""
    if rec is not None and rec.get("crack_released_share") is not None:
        return rec["crack_released_share"]
    path = os.path.join(out, "runs", scene, "fem_summary.json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        s = json.load(f)
    total = s.get("cohesive_dissipation_J") or 0.0
    if "crack_energy_released_J" not in s or total <= 0.0:
        return None
    return s["crack_energy_released_J"] / total


def current_sources_note(records):
    """What the page's runs are to the tree's FEM sources: the same digests, or runs that the
    sources' recorded moves of code (scripts/fem_source_digest.py, SAME_RUNS) make the same."""
    current = {g: fsd.digest(None, g) for g in fsd.GEOMETRIES}
    moved = sorted({(r["geometry"], r.get("fem_digest"), current[r["geometry"]]) for r in records
                    if r.get("geometry") in current and r.get("fem_digest") != current[r["geometry"]]})
    if not moved:
        return "the tree's FEM sources"
    return "the tree's FEM sources compute the same (" + ", ".join(
        f"{g} {new} moved code of {old} without changing its runs" for g, old, new in moved) + \
        "; SAME_RUNS in scripts/fem_source_digest.py)"


def page_header(records, args, command):
    """Records, options and command -> the page's title, provenance, scene count and partial-study notice."""
    missing = getattr(args, "missing", [])
    times = [r["finished_utc"] for r in records if r.get("finished_utc")]
    lines = [
        "# FEM reference on scenes drawn at random",
        "",
        f"Made by `{command}` on {provenance.machine()}, {provenance.utc_now()} UTC, git {provenance.git_revision()}; "
        f"the runs from programs of git {', '.join(sorted({r.get('fem_source', 'unknown') for r in records}))}, "
        "FEM sources per geometry (scripts/fem_source_digest.py) "
        f"{', '.join(sorted({r.get('geometry', '?') + ' ' + str(r.get('fem_digest')) for r in records}))}"
        + (f", finished between {min(times)} and {max(times)} UTC" if times else "") + "; "
        + current_sources_note(records) + ".",
        f"Scenes: {len(records) + len(missing)} drawn with seed {args.seed}, family `{args.family}` "
        "(scripts/fem_robustness.py: the ranges are `RANGES` there), "
        f"{args.jobs} run(s) side by side with one assembly thread each.",
        "",
    ]
    if missing:
        lines += [f"**Partial: {len(records)} of {len(records) + len(missing)} scenes run so far** (the study goes on "
                  "with `--resume`); not yet run: " + ", ".join(missing) + ".", ""]
    return lines


def outcome_summary(records, ok, wrong, failed):
    """Records sorted by outcome -> the outcome table, wall times, step cuts, residuals and the checks made."""
    walls = [r["wall_s"] for r in records if r["exit"] == 0]
    cuts = [r.get("step_cuts") or 0 for r in records if r["exit"] == 0]
    return [
        "| outcome | scenes |",
        "|---|---|",
        f"| converged, records consistent | {len(ok)} of {len(records)} |",
        f"| converged, records contradict the forces | {len(wrong)} |",
        f"| stopped with an error | {len(failed)} |",
        "",
        f"Wall time per run: median {median(walls):.0f} s, max {max(walls) if walls else float('nan'):.0f} s. "
        f"Load-step cuts: {sum(cuts)} in all, at most {max(cuts) if cuts else 0} in one run, "
        f"{sum(1 for c in cuts if c)} run(s) with any. "
        f"Steps accepted by the last resort (a stall below 0.5 % of the peak force at 1/256 of the load step, "
        f"reference_fem/README.md): {sum(r.get('last_resort') or 0 for r in records)} in "
        f"{sum(1 for r in records if r.get('last_resort'))} run(s); the largest residual any accepted step left: "
        f"{100 * max([r.get('largest_residual_share') or 0.0 for r in records] + [0.0]):.2g} % of its run's peak force.",
        "",
        "Checks, from each run's fem_force_depth.csv and fem_summary.json alone (thresholds `CHECKS`):",
        f"shaft friction above {fr.CHECKS['intact_friction_N']} N and {fr.CHECKS['intact_friction_share']:.0%} "
        "of the force while no layer is punctured; a force drop during insertion of more than "
        f"{fr.CHECKS['drop_N']} N and {fr.CHECKS['drop_share']:.0%} within {fr.CHECKS['drop_window_mm']} mm "
        f"with no layer changing state within {fr.CHECKS['state_window_mm']} mm; a layer punctured before "
        "the one above it or a state going back; the summary's punctures not those of the state columns; "
        "a cutting part below zero or above the force beyond friction.",
        "",
    ]


def failures_section(failed, wrong):
    """Runs that stopped and runs whose records contradict the forces -> the Failures table (empty if none)."""
    lines = []
    if failed or wrong:
        lines += ["## Failures", "", "| scene | what | |", "|---|---|---|"]
        for r in failed:
            lines.append(f"| {r['scene']} | error | {r['error']} |")
        for r in wrong:
            lines.append(f"| {r['scene']} | inconsistent | {'; '.join(r['problems'])} |")
        lines.append("")
    return lines


def crack_energy_section(records, out):
    """Records and OUT -> the section on the share of crack dissipation from stored energy (empty without runs)."""
    lines = []
    shares = [q for r in records if (q := released_share(out, r["scene"], r)) is not None]
    if shares:
        lines += ["## The cutting part and crack runs", "",
                  "The cutting part of the force is the crack's dissipation per unit advance, at most the force "
                  "beyond friction (reference_fem/README.md); what a crack run dissipates beyond that is energy "
                  "the tissue had stored (`crack_energy_released_J`). Its share of the crack's dissipation: "
                  f"median {100 * median(shares):.0f} %, max {100 * max(shares):.0f} % over {len(shares)} runs.", ""]
    return lines


def scene_table(records):
    """Records -> the table of every scene: its draw, its run and its outcome."""
    lines = ["## Every scene", "",
             "Scene files in `scenes/`; `puncture fem scenes/<scene>.json` runs one again.", "",
             "| scene | tip | skin / fat / muscle mm | speed mm/s | target mm | hold s | wall s | steps | cuts | punctures (layer mm N) | outcome |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in records:
        th = " / ".join(f"{t:g}" for t in r["thickness_mm"])
        pun = "; ".join(f"{n} {d:g} {f:.3g}" for n, d, f in r.get("punctures", []))
        outcome = "error" if r["exit"] else ("inconsistent" if r["problems"] else "ok")
        lines.append(f"| {r['scene']} | {r['tip']} | {th} | {r['speed_mm_per_s']:g} | {r['target_mm']:g} | "
                     f"{r['hold_s']:g} | {r['wall_s']:.0f} | {r.get('load_steps', '')} | {r.get('step_cuts', '')} | "
                     f"{pun} | {outcome} |")
    return lines


def cluster_section():
    """-> the page's closing section: how to run the study as cluster tasks, or resume it."""
    return ["", "## On a cluster", "",
            "Each scene is one task (`--only I` draws the scenes and runs scene I alone, writing "
            "`results/<scene>.json`); `--collect` then writes this page from those files. A Slurm array:",
            "", "```bash",
            "#SBATCH --array=0-59 --cpus-per-task=1",
            "python3 scripts/fem_robustness_study.py --count 60 --seed 48 --only $SLURM_ARRAY_TASK_ID --out $OUT",
            "# after the array:",
            "python3 scripts/fem_robustness_study.py --count 60 --seed 48 --collect --out $OUT", "```", "",
            "On one machine a study stopped part way goes on with `--resume` (the scenes with a result from "
            "the current FEM sources are kept); `--collect --partial` writes this page from the results so far.",
            ""]


def page(records, args, command):
    """Records, options and command -> the text of OUT/README.md."""
    ok = [r for r in records if r["exit"] == 0 and not r["problems"]]
    failed = [r for r in records if r["exit"] != 0]
    wrong = [r for r in records if r["exit"] == 0 and r["problems"]]
    lines = page_header(records, args, command)
    lines += outcome_summary(records, ok, wrong, failed)
    lines += failures_section(failed, wrong)
    lines += crack_energy_section(records, args.out)
    lines += scene_table(records)
    lines += cluster_section()
    return "\n".join(lines)


def runs_csv(records):
    head = ("scene,tip,skin_mm,fat_mm,muscle_mm,speed_mm_per_s,target_mm,hold_s,exit,wall_s,load_steps,step_cuts,"
            "steps_continued,steps_accepted_at_stall,punctures,outcome")
    out = [head]
    for r in records:
        pun = " ".join(f"{n}@{d:g}mm/{f:.4g}N" for n, d, f in r.get("punctures", []))
        outcome = ("error: " + r["error"]) if r["exit"] else ("; ".join(r["problems"]) or "ok")
        cells = [r["scene"], r["tip"]] + [f"{t:g}" for t in r["thickness_mm"]] + [
            f"{r['speed_mm_per_s']:g}", f"{r['target_mm']:g}", f"{r['hold_s']:g}", str(r["exit"]), f"{r['wall_s']:.1f}",
            str(r.get("load_steps", "")), str(r.get("step_cuts", "")), str(r.get("continued", "")),
            str(r.get("accepted_at_stall", "")), pun, '"' + outcome.replace('"', "'") + '"']
        out.append(",".join(cells))
    return "\n".join(out) + "\n"


def collect_records(scenes, args):
    """The records in OUT from the current FEM sources of each scene's geometry (this tree's) and the
    scenes without one; without --partial a scene without a current record stops the collection."""
    digests = {g: fsd.digest(None, g) for g in fsd.GEOMETRIES}
    records, missing = [], []
    for s in scenes:
        rec = current_record(args.out, s, digests)
        if rec is None and not args.partial:
            old = existing_result(args.out, s["name"])
            why = "no result" if old is None else "a result from other FEM sources"
            sys.exit(f"fem_robustness_study: {why} for {s['name']} in {args.out}/results: run again with --resume")
        if rec is None:
            missing.append(s["name"])
        else:
            records.append(rec)
    return records, missing


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--count", type=int, default=60)
    ap.add_argument("--seed", type=int, default=48)
    ap.add_argument("--family", choices=["full", "small"], default="full")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default=os.path.join(fr.ROOT, "results", "fem_robustness"))
    ap.add_argument("--build", default=os.environ.get("PUNCTURE_BUILD_DIR", os.path.join(fr.ROOT, "build")))
    ap.add_argument("--only", type=int, default=-1, help="run scene ONLY alone (a cluster task)")
    ap.add_argument("--collect", action="store_true", help="write the page from the results in OUT")
    ap.add_argument("--partial", action="store_true", help="with --collect: scenes without a result are listed "
                    "as not yet run (the page says so) instead of stopping")
    ap.add_argument("--resume", action="store_true", help="keep the scenes that have a result from the same FEM "
                    "sources; run the others")
    args = ap.parse_args()
    binary = os.path.join(args.build, "apps", "puncture")
    command = "python3 scripts/fem_robustness_study.py " + " ".join(sys.argv[1:])
    scenes = scenes_of(args.count, args.seed, args.family)
    for d in ("scenes", "runs", "results"):
        os.makedirs(os.path.join(args.out, d), exist_ok=True)
    for s in scenes:
        fr.write_scene(s, os.path.join(args.out, "scenes", s["name"] + ".json"))
    if args.collect:
        records, args.missing = collect_records(scenes, args)
    elif args.only >= 0:
        if args.only >= len(scenes):
            sys.exit(f"fem_robustness_study: --only {args.only}: there are {len(scenes)} scenes")
        rec = run_one(scenes[args.only], args.out, binary, 1, current_fem_sources(binary))
        print(json.dumps(rec))
        return 0 if rec["exit"] == 0 and not rec["problems"] else 1
    else:
        if not os.access(binary, os.X_OK):
            sys.exit(f"fem_robustness_study: {binary} not built (bash scripts/build.sh)")
        threads = 1 if args.jobs > 1 else max(1, os.cpu_count() or 1)
        sources = current_fem_sources(binary)
        records = [current_record(args.out, s, sources[1]) if args.resume else None for s in scenes]
        if args.resume:
            print(f"fem_robustness_study: {sum(r is not None for r in records)} of {len(scenes)} scenes have a "
                  f"result from the current FEM sources of their geometry {sources[1]}; running the others",
                  flush=True)
        t0 = time.monotonic()
        with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
            futures = {pool.submit(run_one, s, args.out, binary, threads, sources): i for i, s in enumerate(scenes)
                       if records[i] is None}
            for n, f in enumerate(concurrent.futures.as_completed(futures), 1):
                i = futures[f]
                r = records[i] = f.result()
                outcome = "error: " + r["error"] if r["exit"] else ("; ".join(r["problems"]) or "ok")
                print(f"[{n}/{len(futures)}, {time.monotonic() - t0:.0f} s] {r['scene']}: {r['wall_s']:.0f} s, "
                      f"{outcome}", flush=True)
    results_io.write_text(os.path.join(args.out, "README.md"), page(records, args, command))
    results_io.write_text(os.path.join(args.out, "runs.csv"), runs_csv(records))
    good = all(r["exit"] == 0 and not r["problems"] for r in records) and not getattr(args, "missing", [])
    print(f"fem_robustness_study: {sum(1 for r in records if r['exit'] == 0 and not r['problems'])} of "
          f"{len(records)} converged with consistent records; page {args.out}/README.md")
    return 0 if good else 1


if __name__ == "__main__":
    sys.exit(main())
