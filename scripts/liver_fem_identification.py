#!/usr/bin/python3
"""liver_fem_identification.py: the FEM reference of the liver scene beside the
measured Okamura 2004 insertion, and the identification of its three most
uncertain parameters against that curve by a derivative-free optimiser
(Nelder-Mead on the logarithms) over FEM runs.

Parameters identified (everything else stays at its literature value):
  capsule cohesive strength sigma_c (kPa)  layers[0].puncture.cohesive_strength_kPa
  parenchyma Young's modulus E (kPa)      layers[1].material.youngs_modulus_kPa
  shaft friction coefficient mu           layers[*].shaft_friction (static 1.5 mu)
Objective (dimensionless), on the insertion from contact to FIT_DEPTH_MM of tip
depth (beyond it the trace's drops are vessels the scene does not model):
  J = (RMSE of the force / measured capsule puncture force)^2
      + (puncture force error / measured)^2 + (puncture depth error / measured)^2.
During the search the FEM runs stop at FIT_DEPTH_MM + 1 mm; the page compares
full runs (the scene's whole insertion) before and after.

Usage: liver_fem_identification.py SCENE CURVE_CSV OUT_DIR PUNCTURE_BIN
       [--offset-mm 9.5] [--evaluations 24] [--fit-depth-mm 15] [--ranks 2]
Writes OUT_DIR/README.md, identification.json, evaluations.csv (one row per
FEM run, written as it goes: the progress), liver_fem_vs_okamura.png,
liver_identified.json (the scene with the identified values).
"""
import argparse
import collections
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import fem_metrics  # noqa: E402
import provenance  # noqa: E402
import results_io  # noqa: E402

NAMES = ["capsule_cohesive_strength_kPa", "parenchyma_youngs_modulus_kPa", "friction_coefficient"]


def read_curve(path, offset_mm):
    pts = []
    for line in open(path):
        if line.startswith("#") or line.startswith("depth"):
            continue
        d, f = line.strip().split(",")
        pts.append((float(d) - offset_mm, float(f)))
    return pts


def curve_features(pts):
    """Puncture: the largest force before the first drop of more than half of
    it (the capsule); the level after it: mean force over 1-3 mm after the drop."""
    best, best_d = 0.0, None
    for d, f in pts:
        if f > best:
            best, best_d = f, d
        elif best > 0.5 and f < 0.5 * best:
            break
    after = [f for d, f in pts if best_d + 1.0 <= d <= best_d + 3.0]
    return {"puncture_depth_mm": best_d, "puncture_force_N": best,
            "level_after_N": sum(after) / len(after) if after else float("nan")}


def binned(pts, lo, hi, width=0.5):
    """Measured force averaged in bins of `width` mm (several digitised traces)."""
    out = []
    x = lo
    while x < hi:
        v = [f for d, f in pts if x <= d < x + width]
        if v:
            out.append((x + 0.5 * width, sum(v) / len(v)))
        x += width
    return out


def interp(rows, d):
    for a, b in zip(rows, rows[1:]):
        if a[0] <= d <= b[0]:
            t = (d - a[0]) / (b[0] - a[0]) if b[0] > a[0] else 0.0
            return a[1] + t * (b[1] - a[1])
    return None


def fem_features(summary, rows):
    ins = [(fem_metrics.value(r, "depth_mm"), fem_metrics.value(r, "force_N")) for r in rows
           if r["phase"] == "insertion" and fem_metrics.value(r, "depth_mm") >= 0.0]
    p = summary.get("punctures", [])
    first = p[0] if p else None
    after = []
    if first:
        after = [f for d, f in ins if first["depth_mm"] + 1.0 <= d <= first["depth_mm"] + 3.0]
    fr = fem_metrics.friction_per_mm(summary, rows)
    return ins, {"puncture_depth_mm": first["depth_mm"] if first else None,
                 "puncture_force_N": first["force_N"] if first else None,
                 "level_after_N": sum(after) / len(after) if after else None,
                 "friction_per_mm_N": fr[0] if fr else None}


def objective(ins, feat, measured, bins):
    ref_F = measured["puncture_force_N"]
    err = []
    for d, f in bins:
        v = interp(ins, d)
        if v is not None:
            err.append(v - f)
    rmse = math.sqrt(sum(e * e for e in err) / len(err)) if err else float("inf")
    if feat["puncture_force_N"] is None:
        return {"J": 1e3, "rmse_N": rmse}
    ef = (feat["puncture_force_N"] - ref_F) / ref_F
    ed = (feat["puncture_depth_mm"] - measured["puncture_depth_mm"]) / measured["puncture_depth_mm"]
    return {"J": (rmse / ref_F) ** 2 + ef ** 2 + ed ** 2, "rmse_N": rmse, "force_error": ef, "depth_error": ed}


def with_parameters(scene, x):
    s = json.loads(json.dumps(scene), object_pairs_hook=collections.OrderedDict)
    s["layers"][0]["puncture"]["cohesive_strength_kPa"] = x[0]
    s["layers"][1]["material"]["youngs_modulus_kPa"] = x[1]
    for l in s["layers"]:
        l["shaft_friction"]["coefficient"] = x[2]
        l["shaft_friction"]["static_coefficient"] = 1.5 * x[2]
    return s


def run_fem(scene, work, tag, args, stop_depth_mm=None):
    path = os.path.join(work, f"{tag}.json")
    json.dump(scene, open(path, "w"), indent=2)
    out = os.path.join(work, tag)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    cmd = ["mpirun", "--oversubscribe", "-np", str(args.ranks), args.puncture, "fem", path, "-o", out, "--no-vtu", "-q"]
    if stop_depth_mm is not None:
        cmd += ["--stop-depth", str(stop_depth_mm)]
    t0 = time.time()
    r = subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        lines = [l for l in r.stderr.splitlines() if l.strip() and not l.startswith("---")]
        print(f"  FEM run {tag} failed (exit {r.returncode}): " + " | ".join(lines[:3]), flush=True)
        return None, time.time() - t0
    return fem_metrics.read_fem(out), time.time() - t0


def nelder_mead(f, x0, step, budget):
    """Nelder-Mead (standard coefficients 1, 2, 0.5, 0.5) within `budget` evaluations."""
    n = len(x0)
    simplex = [list(x0)] + [[x0[j] + (step[j] if j == i else 0.0) for j in range(n)] for i in range(n)]
    values = [f(x) for x in simplex]
    evals = n + 1
    while evals < budget:
        order = sorted(range(n + 1), key=lambda i: values[i])
        simplex = [simplex[i] for i in order]
        values = [values[i] for i in order]
        c = [sum(simplex[i][j] for i in range(n)) / n for j in range(n)]
        xr = [c[j] + (c[j] - simplex[-1][j]) for j in range(n)]
        fr = f(xr); evals += 1
        if fr < values[0] and evals < budget:
            xe = [c[j] + 2 * (c[j] - simplex[-1][j]) for j in range(n)]
            fe = f(xe); evals += 1
            simplex[-1], values[-1] = (xe, fe) if fe < fr else (xr, fr)
        elif fr < values[-2]:
            simplex[-1], values[-1] = xr, fr
        else:
            xc = [c[j] + 0.5 * (simplex[-1][j] - c[j]) for j in range(n)]
            fc = f(xc); evals += 1
            if fc < min(fr, values[-1]):
                simplex[-1], values[-1] = xc, fc
            else:
                for i in range(1, n + 1):
                    if evals >= budget:
                        break
                    simplex[i] = [simplex[0][j] + 0.5 * (simplex[i][j] - simplex[0][j]) for j in range(n)]
                    values[i] = f(simplex[i]); evals += 1
    best = min(range(n + 1), key=lambda i: values[i])
    return simplex[best], values[best]


def feature_rows(measured, before, after):
    def fmt(v, unit, digits=2):
        return "n/a" if v is None else f"{v:.{digits}f} {unit}"
    rows = [("contact-to-puncture tenting", "puncture_depth_mm", "mm", 2),
            ("capsule puncture force", "puncture_force_N", "N", 2),
            ("force level 1-3 mm after the puncture", "level_after_N", "N", 2)]
    L = ["| quantity | measured (Okamura 2004, Fig. 1) | FEM, literature values | FEM, identified |", "|---|---|---|---|"]
    for label, key, unit, dg in rows:
        L.append(f"| {label} | {fmt(measured[key], unit, dg)} | {fmt(before[key], unit, dg)} | {fmt(after[key], unit, dg)} |")
    drop = lambda f: None if f["puncture_force_N"] is None or f["level_after_N"] is None else f["puncture_force_N"] - f["level_after_N"]
    L.append(f"| the drop at the puncture | {fmt(drop(measured), 'N')} | {fmt(drop(before), 'N')} | {fmt(drop(after), 'N')} |")
    L.append(f"| shaft friction per unit length | 0.013 N/mm sliding, 0.018 static (Okamura's Karnopp fit, "
             f"../shared/LITERATURE.md) | {fmt(before['friction_per_mm_N'], 'N/mm', 4)} | {fmt(after['friction_per_mm_N'], 'N/mm', 4)} |")
    return L


def plot(path, curve, before, after, fit_depth, note):
    fig, ax = plt.subplots(figsize=(8, 4.8))
    ax.plot([d for d, _ in curve], [f for _, f in curve], ".", ms=2, color="0.5", label="measured (Okamura 2004, bovine liver, 3 mm/s)")
    ax.plot([d for d, _ in before], [f for _, f in before], label="FEM, literature values")
    ax.plot([d for d, _ in after], [f for _, f in after], label="FEM, identified")
    ax.axvspan(0, fit_depth, color="C2", alpha=0.07, label=f"fitted range 0-{fit_depth:g} mm")
    ax.set_xlabel("tip depth below the capsule's rest surface (mm)")
    ax.set_ylabel("needle force (N)")
    ax.set_xlim(-1, max(d for d, _ in curve))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.text(0.01, 0.01, note, fontsize=6)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    results_io.save_figure(fig, path)


def friction_note(feat, x, scene):
    """Why Coulomb friction on this parenchyma cannot give the measured friction."""
    a_mm = scene["needle"]["radius_mm"]
    measured = 0.013  # N/mm, Okamura 2004 Karnopp fit (../shared/LITERATURE.md)
    p_needed = measured / (x[2] * 2 * math.pi * a_mm) * 1e3  # kPa
    mu_shear = x[1] / 3.0  # kPa, incompressible
    fem = feat.get("friction_per_mm_N") or 0.0
    return (f"Shaft friction: the identified FEM gives {fem:.4f} N/mm where the measurement gives {measured} N/mm. With "
            f"Coulomb friction (coefficient {x[2]:.3g}) that measurement needs a radial pressure of about {p_needed:.0f} kPa "
            f"on the shaft, {p_needed / mu_shear:.0f} times the identified parenchyma's shear modulus ({mu_shear:.2f} kPa): "
            "a tissue this soft cannot press that hard on a needle it has been opened around, so the measured friction "
            "of liver is not Coulomb friction on the parenchyma's elastic pressure (adhesion or a pressure-independent "
            "interface shear, which the FEM does not model, are the candidates). The coefficient is therefore not "
            "identifiable from this curve (the search moved it little); the friction is the real-time force law's, "
            "calibrated on the same curve in results/liver_calibration.")


def held_out_rmse(ins, curve, lo, hi):
    err = [interp(ins, d) - f for d, f in binned(curve, lo, hi) if interp(ins, d) is not None]
    return math.sqrt(sum(e * e for e in err) / len(err)) if err else None


def parse_arguments():
    """Command line -> argparse namespace (scene, curve, out_dir, puncture and the options)."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("curve")
    ap.add_argument("out_dir")
    ap.add_argument("puncture")
    ap.add_argument("--offset-mm", type=float, default=9.5)
    ap.add_argument("--evaluations", type=int, default=24)
    ap.add_argument("--fit-depth-mm", type=float, default=15.0)
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--from-evaluations", help="an evaluations.csv of an earlier search: take its best run instead of "
                    "searching again (the page is rewritten from it)")
    return ap.parse_args()


def literature_values(scene):
    """Scene -> its [capsule sigma_c kPa, parenchyma E kPa, friction coefficient] (the search's start)."""
    return [scene["layers"][0]["puncture"]["cohesive_strength_kPa"], scene["layers"][1]["material"]["youngs_modulus_kPa"],
            scene["layers"][1]["shaft_friction"]["coefficient"]]


def read_evaluations(path):
    """evaluations.csv of an earlier search (or None) -> its rows as lists of strings, without the head (or None)."""
    previous = None
    if path:
        with open(path) as f:
            previous = [l.strip().split(",") for l in f if l.strip()][1:]
    return previous


def best_of_evaluations(previous, from_path, log_path):
    """An earlier search's rows -> (its lowest-J parameters, its number of FEM runs); its CSV copied to log_path."""
    if os.path.abspath(from_path) != os.path.abspath(log_path):
        shutil.copyfile(from_path, log_path)
    best = min(previous, key=lambda r: float(r[4]))
    return [float(v) for v in best[1:4]], len(previous)


def search(scene, x0, work, args, measured, bins, log_path):
    """Literature values -> (identified parameters, FEM runs made) by Nelder-Mead on the logarithms; writes evaluations.csv."""
    count = [0]
    log = open(log_path + ".part", "w")  # evaluations.csv.part while the search runs

    def evaluate(logx):
        x = [math.exp(v) for v in logx]
        count[0] += 1
        res, wall = run_fem(with_parameters(scene, x), work, f"eval{count[0]}", args, args.fit_depth_mm + 1.0)
        if res is None:
            J, o, feat = 1e3, {"rmse_N": float("nan")}, {"puncture_depth_mm": None, "puncture_force_N": None}
        else:
            ins, feat = fem_features(*res)
            o = objective(ins, feat, measured, bins)
            J = o["J"]
        log.write(f"{count[0]}," + ",".join(f"{v:.6g}" for v in x) + f",{J:.6g},{o['rmse_N']:.4g},"
                  f"{feat['puncture_depth_mm']},{feat['puncture_force_N']},{wall:.1f}\n")
        log.flush()
        print(f"liver identification: run {count[0]}/{args.evaluations}  " +
              "  ".join(f"{n}={v:.4g}" for n, v in zip(NAMES, x)) + f"  J={J:.4g}  ({wall:.0f} s)", flush=True)
        return J

    log.write("run," + ",".join(NAMES) + ",J,rmse_N,puncture_depth_mm,puncture_force_N,wall_s\n")
    start = [math.log(v) for v in x0]
    best_log, best_J = nelder_mead(evaluate, start, [math.log(2.0)] * 3, args.evaluations)
    log.close()
    os.replace(log_path + ".part", log_path)
    return [math.exp(v) for v in best_log], count[0]


def command_line(args):
    """Options -> the command that made the page, as the page and identification.json give it."""
    return (f"scripts/liver_fem_identification.sh (= liver_fem_identification.py {args.scene} {args.curve} {args.out_dir} "
            f"PUNCTURE --offset-mm {args.offset_mm:g} --evaluations {args.evaluations} --fit-depth-mm {args.fit_depth_mm:g}"
            + (f" --from-evaluations {args.from_evaluations}" if args.from_evaluations else "") + ")")


def write_identified_scene(out_dir, identified, x_best):
    """Identified scene and parameters -> OUT_DIR/liver_identified.json (its description names the values)."""
    identified["description"] += (" Identified against the Okamura curve: " +
                                  ", ".join(f"{n} {v:.4g}" for n, v in zip(NAMES, x_best)) + ".")
    results_io.write_text(os.path.join(out_dir, "liver_identified.json"),
                          json.dumps(identified, indent=2, ensure_ascii=False) + "\n")


def readme_lines(args, command, runs, reused, minutes, x0, x_best, fits, last, scene):
    """Options, parameters and fits (measured, features, objectives, held-out RMSE before/after) -> README.md's lines."""
    measured, feat_b, feat_a, obj_b, obj_a, held_b, held_a = fits
    L = ["# Liver FEM beside a measured insertion (Okamura, Simone & O'Leary 2004)\n",
         f"Command: `{command}`.  ", f"Git {provenance.git_revision()}; machine: {provenance.machine()}; "
         f"date {provenance.utc_now()} UTC; " +
         (f"the search's {runs} FEM runs are those of `evaluations.csv` (an earlier run of the same script on "
          f"the same scene and code); this run made the two whole insertions in {minutes:.1f} min.\n"
          if reused else f"{runs + 2} FEM runs in {minutes:.1f} min.\n"),
         f"Scene `{args.scene}` (capsule 0.5 mm, parenchyma 50 mm, 18 G bevel needle at 3 mm/s, every value with its "
         "source in the scene). Measured: `../shared/data/okamura2004_liver_depth_force.csv` (bovine liver ex vivo, "
         f"digitised Fig. 1; depth shifted by {args.offset_mm:g} mm so that 0 is the contact).\n",
         "![FEM and measured force against depth](liver_fem_vs_okamura.png)\n"]
    L += feature_rows(measured, feat_b, feat_a)
    L += ["", "| | capsule sigma_c (kPa) | parenchyma E (kPa) | friction coefficient | objective J | force RMSE, fitted 0-"
          f"{args.fit_depth_mm:g} mm (N) | force RMSE, not fitted {args.fit_depth_mm:g}-{last:.0f} mm (N) |",
          "|---|---|---|---|---|---|---|",
          f"| literature | {x0[0]:.4g} | {x0[1]:.4g} | {x0[2]:.4g} | {obj_b['J']:.4g} | {obj_b['rmse_N']:.3f} | "
          f"{held_b:.3f} |" if held_b is not None else "| literature | | | | | | |",
          f"| identified | {x_best[0]:.4g} | {x_best[1]:.4g} | {x_best[2]:.4g} | {obj_a['J']:.4g} | {obj_a['rmse_N']:.3f} | "
          f"{held_a:.3f} |" if held_a is not None else "| identified | | | | | | |", "",
          f"Objective J = (force RMSE / measured capsule puncture force)^2 + (puncture force error / measured)^2 + "
          f"(puncture depth error / measured)^2 over 0-{args.fit_depth_mm:g} mm of tip depth, minimised by Nelder-Mead on "
          f"the logarithms of the three parameters ({runs} FEM runs stopped at {args.fit_depth_mm + 1:g} mm; "
          "evaluations.csv lists each). Beyond the fitted range the measured trace rises and drops again at structures "
          "inside the liver (vessels) that the two-layer scene does not model; its RMSE there is shown, not fitted. "
          "The identified scene is `liver_identified.json`.", "", friction_note(feat_a, x_best, scene)]
    return L


def main():
    """Command line -> the FEM runs, and README.md, identification.json, the plot and the identified scene in OUT_DIR."""
    args = parse_arguments()
    t_start = time.time()
    scene = json.load(open(args.scene), object_pairs_hook=collections.OrderedDict)
    curve = read_curve(args.curve, args.offset_mm)
    measured = curve_features(curve)
    bins = binned(curve, 0.0, args.fit_depth_mm)
    x0 = literature_values(scene)
    os.makedirs(args.out_dir, exist_ok=True)
    work = tempfile.mkdtemp()
    log_path = os.path.join(args.out_dir, "evaluations.csv")
    previous = read_evaluations(args.from_evaluations)
    # The whole insertion (the measured curve has no withdrawal).
    target = scene["insertion"]["target_depth_mm"]
    print("liver identification: FEM at the literature values (whole insertion)", flush=True)
    full_before, _ = run_fem(with_parameters(scene, x0), work, "before", args, target)
    if full_before is None:
        sys.exit("liver identification: the FEM run at the literature values failed")
    if previous:
        x_best, runs = best_of_evaluations(previous, args.from_evaluations, log_path)
    else:
        x_best, runs = search(scene, x0, work, args, measured, bins, log_path)
    print("liver identification: FEM at the identified values (whole insertion)", flush=True)
    identified = with_parameters(scene, x_best)
    full_after, _ = run_fem(identified, work, "after", args, target)
    if full_after is None:
        sys.exit("liver identification: the FEM run at the identified values failed")
    ins_b, feat_b = fem_features(*full_before)
    ins_a, feat_a = fem_features(*full_after)
    obj_b, obj_a = objective(ins_b, feat_b, measured, bins), objective(ins_a, feat_a, measured, bins)
    last = max(d for d, _ in curve)
    held_b, held_a = held_out_rmse(ins_b, curve, args.fit_depth_mm, last), held_out_rmse(ins_a, curve, args.fit_depth_mm, last)
    command = command_line(args)
    stamp = (f"bash scripts/liver_fem_identification.sh, git {provenance.git_revision()}, {provenance.machine()}, "
             f"{provenance.utc_now()} UTC")
    plot(os.path.join(args.out_dir, "liver_fem_vs_okamura.png"), curve, ins_b, ins_a, args.fit_depth_mm, stamp)
    write_identified_scene(args.out_dir, identified, x_best)
    result = {"parameters": NAMES, "literature": x0, "identified": x_best, "objective_before": obj_b,
              "objective_after": obj_a, "measured": measured, "fem_before": feat_b, "fem_after": feat_a,
              "held_out_rmse_N": {"before": held_b, "after": held_a, "range_mm": [args.fit_depth_mm, last]},
              "fem_runs": runs + 2, "wall_s": time.time() - t_start, "command": command}
    results_io.write_text(os.path.join(args.out_dir, "identification.json"), json.dumps(result, indent=2) + "\n")
    fits = (measured, feat_b, feat_a, obj_b, obj_a, held_b, held_a)
    L = readme_lines(args, command, runs, bool(previous), (time.time() - t_start) / 60, x0, x_best, fits, last, scene)
    results_io.write_text(os.path.join(args.out_dir, "README.md"), "\n".join(L) + "\n")
    shutil.rmtree(work, ignore_errors=True)
    print("wrote", args.out_dir)


if __name__ == "__main__":
    main()
