#!/usr/bin/python3
"""ablation.py: what each mechanism of the real-time model buys, out of sample.

Rows (cumulative): the seed paper's model as written (scenes/paper_table2.json);
then the tuned preset's force meshes without their stiffening (linear springs:
k_a = z_v = 0), the paper's ring-w breakthrough and no other mechanism; then,
one at a time, the tuned preset's stiffening (in the mesh: k_a and z_v where
the surface fit identified them; of the tip spring elsewhere), cutting, shaft
friction, the critical-force breakthrough, the rupture release (the load at a
break let go over the release length instead of at once), the breakthrough's
rate law (its threshold x (v / v_ref)^n, n identified with d at two speeds), the rate laws of
the cutting force (C [(1 - b) + b v / v_ref]) and of the release length (l (v_b / v_ref)^m), b
and m identified with d and n, the shaft's contact pressure relaxing with each layer's Prony
series (no fitted parameter), the coupled surfaces
(= the tuned preset as calibrated), with --slab-rule the tuned preset with its
slab rule on the cases that change the slab (`validate --slab-rule`: only the
other slab's parameters differ from the row before), and layer interaction in
place of the coupled surfaces (without the slab rule). Each row is validated (`puncture validate SCENE --cases
CASES_JSON`, FEM from out/.fem_cache) on every case of the cases file; its tick
cost is the wall time of `puncture run` on the default trajectory (ticks with
contact: mean and p99).

Usage: ablation.py TUNED_PRESET PAPER_SCENE CASES_JSON OUT_DIR PUNCTURE_BIN [--ranks 2] [--slab-rule RULE]
Writes OUT_DIR/README.md (table) and OUT_DIR/ablation.json.
"""
import argparse
import collections
import json
import os
import subprocess

import provenance
import results_io


def rows(tuned, paper, slab_rule=None):
    """(label, scene, slab rule file or None) per row."""
    def variant(effects, ring_rule, release=True, rate=True, cutting_rate=True, relaxation=True):
        s = json.loads(json.dumps(tuned), object_pairs_hook=collections.OrderedDict)
        s["effects"] = effects
        if not relaxation:
            for l in s["layers"]:
                l["force_law"].get("friction", {}).pop("pressure_relaxation", None)
        if not cutting_rate:
            for l in s["layers"]:
                l["force_law"].pop("cutting_rate", None)
                l["force_law"].pop("rupture_release_rate", None)
        if not release:
            for l in s["layers"]:
                l["force_law"]["rupture_release_mm"] = 0.0
        if not rate:
            for l in s["layers"]:
                l["force_law"]["breakthrough"].pop("rate_exponent", None)
                l["force_law"]["breakthrough"].pop("reference_speed_mm_per_s", None)
        if "stiffening" not in effects:
            for l in s["layers"]:
                l["force_mesh"].pop("surface_axial_stiffness_N_per_mm", None)
                l["force_mesh"].pop("virtual_stiffening_mm", None)
        if ring_rule:
            for l, p in zip(s["layers"], paper["layers"]):
                l["force_law"]["breakthrough"] = p["force_law"]["breakthrough"]
        return s
    base = ["surface_force", "damping", "resumption"]
    tuned_row = variant(base + ["stiffening", "cutting", "friction", "coupled_surfaces"], False)
    table = [
        ("paper model (Table 1 law, Table 2 values, ring rule)", paper),
        ("tuned force meshes, linear springs, ring rule, no other mechanism", variant(base, True)),
        ("+ stiffening (in the mesh where identified from the surface, else of the tip spring)",
         variant(base + ["stiffening"], True)),
        ("+ cutting", variant(base + ["stiffening", "cutting"], True, False, cutting_rate=False, relaxation=False)),
        ("+ shaft friction", variant(base + ["stiffening", "cutting", "friction"], True, False, cutting_rate=False, relaxation=False)),
        ("+ critical-force breakthrough",
         variant(base + ["stiffening", "cutting", "friction"], False, False, False, cutting_rate=False, relaxation=False)),
        ("+ rupture release", variant(base + ["stiffening", "cutting", "friction"], False, True, False, cutting_rate=False, relaxation=False)),
        ("+ breakthrough rate law", variant(base + ["stiffening", "cutting", "friction"], False, cutting_rate=False, relaxation=False)),
        ("+ rate laws of cutting and release", variant(base + ["stiffening", "cutting", "friction"], False, relaxation=False)),
        ("+ shaft pressure relaxation (the layers' Prony series)",
         variant(base + ["stiffening", "cutting", "friction"], False)),
        ("+ coupled surfaces (the tuned preset)", tuned_row),
    ]
    rows_ = [(label, scene, None) for label, scene in table]
    if slab_rule:
        rows_.append((f"+ slab rule on the other slab ({slab_rule})", tuned_row, slab_rule))
    rows_.append(("+ layer interaction (in place of coupled surfaces" + (", without the slab rule)" if slab_rule else ")"),
                  variant(base + ["stiffening", "cutting", "friction", "layer_interaction"], False), None))
    return rows_


def tick_cost(scene_path, puncture, work):
    out = os.path.join(work, "run")
    subprocess.run([puncture, "run", scene_path, "-o", out, "-q", "--no-frames"], check=True)
    t = json.load(open(os.path.join(out, "summary.json")))["tick_timing_us"]
    return t["contact_mean"], t["contact_p99"]


def validate_cases(scene_path, cases_path, work, puncture, ranks, label, slab_rule=None):
    """`puncture validate` on every case: (held-out summary, {case: validation_metrics.json})."""
    out = os.path.join(work, "cases")
    print(f"{label}: puncture validate --cases", flush=True)
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    rule = ["--slab-rule", slab_rule] if slab_rule else []
    r = subprocess.run(["mpirun", "--oversubscribe", "-np", str(ranks), puncture, "validate", scene_path,
                        "--cases", cases_path, "-o", out, "--no-vtk", "-q"] + rule, env=env)
    if r.returncode != 0:
        raise SystemExit(f"{label}: puncture validate failed (exit {r.returncode})")
    summary = json.load(open(os.path.join(out, "heldout_summary.json")))
    metrics = {c["name"]: json.load(open(os.path.join(out, c["name"], "validation_metrics.json")))
               for c in summary["cases"]}
    return summary, metrics


def fmt(v, pattern):
    return "n/a" if v is None else format(v, pattern)


def mean(values):
    v = [x for x in values if x is not None]
    return sum(v) / len(v) if v else None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    for a in ("tuned", "paper", "cases", "out_dir", "puncture"):
        ap.add_argument(a)
    ap.add_argument("--ranks", type=int, default=2)
    ap.add_argument("--slab-rule", default=None, help="the tuned preset's slab rule (adds a row)")
    args = ap.parse_args()
    tuned = json.load(open(args.tuned), object_pairs_hook=collections.OrderedDict)
    paper = json.load(open(args.paper), object_pairs_hook=collections.OrderedDict)
    result = []
    for i, (label, scene, slab_rule) in enumerate(rows(tuned, paper, args.slab_rule)):
        work = os.path.join("out", "ablation", f"row{i}")
        os.makedirs(work, exist_ok=True)
        base_path = os.path.join(work, "scene.json")
        json.dump(scene, open(base_path, "w"), indent=2, ensure_ascii=False)
        mean_us, p99_us = tick_cost(base_path, args.puncture, work)
        summary, metrics = validate_cases(base_path, args.cases, work, args.puncture, args.ranks,
                                          f"ablation row {i + 1} ({label})", slab_rule)
        per_case = []
        for case in summary["cases"]:
            layers = case["layers"]
            per_case.append({"case": case["name"], "held_out": case["held_out"],
                             "force_rmse_relative": metrics[case["name"]]["overall"]["force_rmse_relative"],
                             "deflection_relative_rmse": mean(l["deflection_relative_rmse"] for l in layers),
                             "layers_accepted": sum(1 for l in layers if l["accepted"]), "layers": len(layers)})
        held = [c for c in per_case if c["held_out"]]
        result.append({"row": label, "slab_rule": slab_rule, "tick_contact_mean_us": mean_us, "tick_contact_p99_us": p99_us,
                       "heldout_force_rmse_relative": mean(c["force_rmse_relative"] for c in held),
                       "heldout_deflection_relative_rmse": mean(c["deflection_relative_rmse"] for c in held),
                       "in_sample_force_rmse_relative": mean(c["force_rmse_relative"] for c in per_case if not c["held_out"]),
                       "heldout_layers_accepted": f"{sum(c['layers_accepted'] for c in held)} of {sum(c['layers'] for c in held)}",
                       "cases": per_case})
    command = (f"scripts/results_ablation.sh (ablation.py {args.tuned} {args.paper} {args.cases} {args.out_dir}"
               + (f" --slab-rule {args.slab_rule}" if args.slab_rule else "") + ")")
    L = ["# What each mechanism of the real-time model buys\n",
         f"Command: `{command}`, git {provenance.git_revision()}, {provenance.machine()}, {provenance.utc_now()} UTC.\n",
         "Rows are cumulative. Errors are over the whole insertion against the FEM reference of each case, as a fraction "
         "of the FEM's peak force (force) and of the FEM's largest deflection of each layer before its breakthrough "
         f"(deflection, mean over layers); held out: the mean over the cases of `{args.cases}` the preset was not "
         "calibrated on. Tick cost: `puncture run` on the default trajectory, wall time of the ticks with contact.\n",
         "| model | force RMSE, calibration trajectory (in sample) | force RMSE, held out | deflection RMSE, held out | "
         "layers accepted, held out | tick mean (us) | tick p99 (us) |", "|---|---|---|---|---|---|---|"]
    for r in result:
        L.append(f"| {r['row']} | {fmt(r['in_sample_force_rmse_relative'], '.3f')} | "
                 f"{fmt(r['heldout_force_rmse_relative'], '.3f')} | {fmt(r['heldout_deflection_relative_rmse'], '.2f')} | "
                 f"{r['heldout_layers_accepted']} | {r['tick_contact_mean_us']:.2f} | {r['tick_contact_p99_us']:.2f} |")
    L += ["", "The stiffening, cutting, friction and breakthrough values are the tuned preset's (calibrated with all of them "
          "on), so a row with a mechanism off is that preset without it, not a model refitted without it (d, for one, "
          "was identified with the rate laws on)."]
    if args.slab_rule:
        L += ["", f"Cases that change the slab take the preset's own parameters in every row but the slab-rule row, "
              f"where they come from its slab rule ({args.slab_rule}, fitted on the preset calibrated on a family of "
              "other slabs: `bash scripts/results_slab_rule.sh`); that row differs from the one before only there. "
              "The other rows' models have no slab rule of their own."]
    os.makedirs(args.out_dir, exist_ok=True)
    for name, text in (("ablation.json", json.dumps({"command": command, "rows": result}, indent=2) + "\n"),
                       ("README.md", "\n".join(L) + "\n")):
        results_io.write_text(os.path.join(args.out_dir, name), text)
    print("wrote", args.out_dir)


if __name__ == "__main__":
    main()
