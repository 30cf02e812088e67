#!/usr/bin/python3
"""heldout_validation.py: a tuned real-time model validated, without retuning,
on cases it was not calibrated on (other speeds, depth and hold, another slab),
beside its calibration trajectory.

Usage: heldout_validation.py MODEL_SCENE CASES_JSON OUT_DIR PUNCTURE_BIN [--ranks 2]

For each case of CASES_JSON (validation/cases/default_heldout.json) the model
scene with the case's overrides (insertion fields; layer_thickness_mm) runs
through `puncture validate` (the FEM of the case comes from out/.fem_cache or
is computed). Kept per case in OUT_DIR/<case>/: validation_metrics.json,
validation_summary.md and the plots (the VTK series stay in out/heldout/).
Writes OUT_DIR/heldout_summary.json
  {"cases": [{"name", "held_out", "scene", "layers": [{"layer",
    "force_rmse_relative", "deflection_relative_rmse", "puncture_depth_error_mm",
    "puncture_force_error_relative", "accepted"}]}]}
and OUT_DIR/heldout_summary.md. A layer is accepted when `puncture validate`
accepts it (pressing and cutting force RMSE <= 10 % of the peak, puncture depth
within L, puncture force within 10 %) and its deflection RMSE before the
breakthrough is <= 15 % of the FEM's largest deflection.
"""
import argparse
import collections
import json
import os
import shutil
import subprocess
import sys

import provenance
import results_io

KEEP = ["validation_metrics.json", "validation_summary.md", "force_depth.png", "deflection_profiles.png",
        "layer_errors.png"]


def case_scene(model, case):
    s = json.loads(json.dumps(model), object_pairs_hook=collections.OrderedDict)
    s["name"] = f"{model['name']}_{case['name']}"
    ov = case.get("overrides", {})
    for k, v in ov.get("insertion", {}).items():
        if k not in s["insertion"]:
            raise SystemExit(f"case {case['name']}: unknown insertion field {k}")
        s["insertion"][k] = v
    if "layer_thickness_mm" in ov:
        t = ov["layer_thickness_mm"]
        if len(t) != len(s["layers"]):
            raise SystemExit(f"case {case['name']}: layer_thickness_mm needs {len(s['layers'])} values")
        for layer, mm in zip(s["layers"], t):
            layer["thickness_mm"] = mm
    unknown = set(ov) - {"insertion", "layer_thickness_mm"}
    if unknown:
        raise SystemExit(f"case {case['name']}: unknown overrides {sorted(unknown)}")
    return s


def validate_case(model, case, work, puncture, ranks, label):
    """The model scene with the case's overrides through `puncture validate`
    into work/<case>: returns (scene path, report folder, validation metrics)."""
    scene_path = os.path.join(work, f"{case['name']}.json")
    json.dump(case_scene(model, case), open(scene_path, "w"), indent=2, ensure_ascii=False)
    report = os.path.join(work, case["name"])
    print(f"{label}: case {case['name']}", flush=True)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    r = subprocess.run(["mpirun", "--oversubscribe", "-np", str(ranks), puncture, "validate", scene_path,
                        "-o", report, "-q"], env=env)
    if r.returncode != 0:
        sys.exit(f"{label}: puncture validate failed on case {case['name']} (exit {r.returncode})")
    return scene_path, report, json.load(open(os.path.join(report, "validation_metrics.json")))


def layer_rows(metrics):
    acc = {a["layer"]: a for a in metrics["acceptance"]}
    rows = []
    for l in metrics["layers"]:
        a = acc.get(l["layer"], {})
        frc = a.get("puncture_force_error_relative", {})
        reasons = []
        for key, label, scale, unit in (("pressing_and_cut_force_rmse_relative", "force RMSE", 1.0, ""),
                                        ("puncture_depth_error_m", "puncture depth", 1e3, " mm"),
                                        ("puncture_force_error_relative", "puncture force", 1.0, ""),
                                        ("deflection_before_relative", "deflection RMSE before the break", 1.0, ""),
                                        ("deflection_after_relative", "deflection RMSE after the break", 1.0, "")):
            t = a.get(key)
            if t is None:
                raise SystemExit(f"validation_metrics.json: acceptance of {l['layer']} has no {key} (an older puncture?)")
            if t.get("available") and not t.get("met"):
                reasons.append(f"{label} {t['value'] * scale:.3g}{unit} beyond {t['limit'] * scale:.3g}{unit}")
            elif not t.get("available", True):
                reasons.append(f"{label}: {t.get('note', 'not available')}")
        rows.append({
            "layer": l["layer"],
            "force_rmse_relative": a.get("pressing_and_cut_force_rmse_relative", {}).get("value"),
            "deflection_relative_rmse": a["deflection_before_relative"].get("value"),
            "deflection_after_break_relative_rmse": a["deflection_after_relative"].get("value"),
            "puncture_depth_error_mm": l.get("puncture_depth_error_mm"),
            "puncture_force_error_relative": frc.get("value"),
            "accepted": bool(a.get("accepted")),
            "misses": reasons,
        })
    return rows


def fmt(v, pattern):
    return "n/a" if v is None else format(v, pattern)


def markdown(summary, cases_path, model_path, command, model_note):
    L = ["# Held-out validation of the tuned real-time model\n",
         f"Command: `{command}`, git {provenance.git_revision()}, {provenance.machine()}, {provenance.utc_now()} UTC.\n",
         f"Model: `{model_path}` ({model_note}). Cases: `{cases_path}`. "
         "Every case but the calibration trajectory is held out: the model was not tuned on it. Acceptance per layer: "
         "pressing and cutting force RMSE <= 10 % of the FEM peak, puncture depth within L, puncture force within "
         "10 %, deflection RMSE of the layer's surface <= 15 % of the FEM's largest deflection before the "
         "breakthrough and <= 25 % after it (the acceptance of `puncture validate`).\n",
         "| case | held out | layer | force RMSE / peak | deflection RMSE / largest, before the break | after the break | "
         "puncture depth error (mm) | puncture force error | accepted | what misses |",
         "|---|---|---|---|---|---|---|---|---|---|"]
    for c in summary["cases"]:
        for l in c["layers"]:
            L.append(f"| {c['name']} | {'yes' if c['held_out'] else 'no (in sample)'} | {l['layer']} | "
                     f"{fmt(l['force_rmse_relative'], '.3f')} | {fmt(l['deflection_relative_rmse'], '.2f')} | "
                     f"{fmt(l['deflection_after_break_relative_rmse'], '.2f')} | "
                     f"{fmt(l['puncture_depth_error_mm'], '+.2f')} | {fmt(l['puncture_force_error_relative'], '+.3f')} | "
                     f"{'yes' if l['accepted'] else 'no'} | {'; '.join(l['misses']) or '-'} |")
    held = [l for c in summary["cases"] if c["held_out"] for l in c["layers"]]
    ok = sum(1 for l in held if l["accepted"])
    L += ["", f"Held out: {ok} of {len(held)} layer-cases accepted. Rules for cases that change the slab are in the "
          "cases file. Each case's report (validation_summary.md, plots) is in its folder."]
    for c in summary["cases"]:
        for key in ("rule", "note"):
            if c.get(key):
                L.append(f"\n`{c['name']}` ({key}): {c[key]}.")
    return "\n".join(L) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("model")
    ap.add_argument("cases")
    ap.add_argument("out_dir")
    ap.add_argument("puncture")
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--model-note", default="calibrated on the calibration trajectory only",
                    help="how the model was calibrated (which references), for the page")
    args = ap.parse_args()
    model = json.load(open(args.model), object_pairs_hook=collections.OrderedDict)
    cases = json.load(open(args.cases))["cases"]
    work = os.path.join("out", "heldout")
    os.makedirs(work, exist_ok=True)
    os.makedirs(args.out_dir, exist_ok=True)
    summary = {"model": args.model, "model_note": args.model_note, "cases_file": args.cases, "cases": []}
    for i, case in enumerate(cases):
        scene_path, report, metrics = validate_case(model, case, work, args.puncture, args.ranks,
                                                    f"heldout {i + 1}/{len(cases)}")
        dest = os.path.join(args.out_dir, case["name"])
        os.makedirs(dest, exist_ok=True)
        for f in KEEP:
            if os.path.exists(os.path.join(report, f)):
                shutil.copyfile(os.path.join(report, f), os.path.join(dest, f + ".part"))
                os.replace(os.path.join(dest, f + ".part"), os.path.join(dest, f))
        summary["cases"].append({"name": case["name"], "held_out": bool(case.get("overrides")),
                                 "scene": scene_path, "rule": case.get("rule"), "note": case.get("note"),
                                 "layers": layer_rows(metrics)})
    command = f"scripts/results_heldout.sh (heldout_validation.py {args.model} {args.cases} {args.out_dir})"
    summary["provenance"] = {"command": command, "git_revision": provenance.git_revision(),
                             "machine": provenance.machine(), "date_utc": provenance.utc_now()}
    for name, text in (("heldout_summary.json", json.dumps(summary, indent=2) + "\n"),
                       ("heldout_summary.md", markdown(summary, args.cases, args.model, command, args.model_note))):
        results_io.write_text(os.path.join(args.out_dir, name), text)
    print("wrote", args.out_dir)


if __name__ == "__main__":
    main()
