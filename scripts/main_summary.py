#!/usr/bin/env python3
"""main_summary.py: what `bash scripts/main.sh` prints after its run: the tuned model's
punctures beside the FEM reference's (the committed validation of the same preset), with the
error, and where the paper's model and the validation reports are.

usage: main_summary.py RUN_DIR [--validation results/validation_tuned]

In:  RUN_DIR/summary.json (`puncture run`'s puncture_events: layer, depth_mm);
     VALIDATION/layer_metrics.csv (per layer the FEM's and the model's puncture depth and force
     as `puncture validate` takes them: the force is the peak of the layer's pressing) and its
     provenance lines (command, git revision, date). The depths are this run's; the forces are
     the committed validation's, and a line says so if this run's depths differ from the ones
     it validated (the validation would then be stale).
Out: a table on stdout; exit 2 with a message naming the file if an input is missing.
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from results_io import number, read_csv_comments  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run_dir")
    ap.add_argument("--validation", default="results/validation_tuned")
    args = ap.parse_args()
    summary_path = os.path.join(args.run_dir, "summary.json")
    metrics_path = os.path.join(args.validation, "layer_metrics.csv")
    for p in (summary_path, metrics_path):
        if not os.path.exists(p):
            sys.exit(f"main_summary: {p}: missing")
    with open(summary_path) as f:
        events = {e["layer"]: e for e in json.load(f).get("puncture_events", [])}
    comments, rows = read_csv_comments(metrics_path)
    fem = {r["layer"]: r for r in rows}
    prov = {k.strip(): v.strip() for k, _, v in (c.partition(":") for c in comments)}  # "# key: value"
    print("")
    print("Punctures of the tuned model (this run) beside the FEM reference's")
    print(f"(FEM: {args.validation}/, `{prov.get('command', '?')}`, git {prov.get('git_revision', '?')}, "
          f"{prov.get('date_utc', prov.get('date', '?'))}):")
    print("")
    print(f"{'layer':<8} {'model mm':>9} {'FEM mm':>8} {'error mm':>9}   {'model N':>8} {'FEM N':>7} {'error':>7}")
    stale = []
    for layer, r in fem.items():
        e = events.get(layer)
        fd, ff = number(r.get("fem_puncture_depth_mm")), number(r.get("fem_puncture_force_N"))
        vd, vf = number(r.get("realtime_puncture_depth_mm")), number(r.get("realtime_puncture_force_N"))
        if e is None:
            print(f"{layer:<8} {'none':>9} {fd:>8.2f}")
            continue
        md = e["depth_mm"]
        if not abs(md - vd) <= 0.005:
            stale.append(layer)
        print(f"{layer:<8} {md:>9.2f} {fd:>8.2f} {md - fd:>+9.2f}   {vf:>8.3f} {ff:>7.3f} {100 * (vf - ff) / ff:>+6.1f}%")
    print("(Depths: this run. Forces: the peak of each layer's pressing, as the validation took them.")
    print("In sample: the preset was calibrated against the FEM on this trajectory; the cases it never saw")
    print("are judged in results/validation_heldout/heldout_summary.md.)")
    if stale:
        print(f"Note: this run punctures {', '.join(stale)} elsewhere than the validated model did: "
              f"{args.validation}/ is stale (bash scripts/results_validation.sh remakes it).")
    print("")
    print("The validation report: results/validation_tuned/validation_summary.md. The paper's Table 2")
    print("model as published:")
    print("build/apps/puncture run scenes/default.json (its punctures are far from the FEM's:")
    print("results/validation_paper_table2/).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
