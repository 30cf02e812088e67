#!/usr/bin/python3
"""speed_law.py: how the tuned preset's punctures follow the insertion speed, beside the FEM's.

Reads the output of `puncture validate PRESET --cases validation/cases/default_speeds.json -o OUT_DIR`
(each case's validation_metrics.json: the puncture depth and force of both models per layer, the
FEM's from its state columns, as the acceptance takes them) and the preset (each layer's critical
force F_c at v_ref and its rate exponent n, core/include/puncture/breakthrough_rate.hpp).
Writes OUT_DIR/speed_law.md (table, which speeds were fitted) and OUT_DIR/speed_law.png
(puncture force and depth against speed per layer, both models).

Usage: speed_law.py PRESET OUT_DIR
"""
import argparse
import json
import os
import re
import sys

import provenance
import results_io

NOTE = re.compile(r"model ([-0-9.eE+]+) mm, ([-0-9.eE+]+) N; reference ([-0-9.eE+]+) mm, ([-0-9.eE+]+) N")


def punctures(metrics_path):
    """{layer: (model depth mm, model force N, FEM depth mm, FEM force N)} of one case."""
    out = {}
    for a in json.load(open(metrics_path))["acceptance"]:
        note = a["puncture_force_error_relative"].get("note", "")
        match = NOTE.search(note)
        if match:
            out[a["layer"]] = tuple(float(x) for x in match.groups())
        elif a["puncture_force_error_relative"].get("available", False):
            sys.exit(f"speed_law.py: {metrics_path}: layer {a['layer']}: cannot read the punctures from '{note}'")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("preset")
    ap.add_argument("out_dir")
    args = ap.parse_args()
    preset = json.load(open(args.preset))
    summary = json.load(open(os.path.join(args.out_dir, "heldout_summary.json")))
    rows = []  # (speed, case, held_out, {layer: tuple})
    for case in summary["cases"]:
        scene = json.load(open(os.path.join(args.out_dir, case["name"], "scene.json")))
        p = punctures(os.path.join(args.out_dir, case["name"], "validation_metrics.json"))
        rows.append((scene["insertion"]["speed_mm_per_s"], case["name"], case["held_out"], p))
    rows.sort()
    if not rows:
        sys.exit("speed_law.py: no cases in " + args.out_dir)
    layers = [l["name"] for l in preset["layers"]]
    law = {l["name"]: l["force_law"]["breakthrough"] for l in preset["layers"]}

    command = f"scripts/results_speeds.sh (speed_law.py {args.preset} {args.out_dir})"
    L = ["# Punctures against insertion speed: tuned preset and FEM", "",
         f"Command: `{command}`, git {provenance.git_revision()}, {provenance.machine()}, {provenance.utc_now()} UTC.", "",
         "Per layer, the puncture depth and the needle's total force there (the FEM's from its state columns, as "
         "`puncture validate`'s acceptance takes them) at each speed. The preset's breakthrough threshold is "
         "F_c (v / v_ref)^n on the layer's surface force (core/README \"Breakthrough\"); n and d were identified at "
         "1 and 10 mm/s (the preset's two-speed step), every other parameter at 10 mm/s; 3 and 20 mm/s were never "
         "seen by the calibration.", "",
         "| layer | n | speed (mm/s) | speeds the rate law was fitted on? | FEM depth (mm) | model depth (mm) | FEM force (N) | model force (N) | force error |",
         "|---|---|---|---|---|---|---|---|---|"]
    for layer in layers:
        n = law[layer].get("rate_exponent", 0.0)
        for speed, name, held_out, p in rows:
            if layer not in p:
                continue
            md, mf, fd, ff = p[layer]
            fitted = "no (held out)" if held_out else "yes"
            L.append(f"| {layer} | {n:.3g} | {speed:g} | {fitted} | {fd:.2f} | {md:.2f} | {ff:.3f} | {mf:.3f} | "
                     f"{100 * (mf - ff) / ff:+.1f} % |")
    L += ["", "![punctures against speed](speed_law.png)", ""]
    results_io.write_text(os.path.join(args.out_dir, "speed_law.md"), "\n".join(L) + "\n")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    colours = ["tab:red", "tab:orange", "tab:blue", "tab:green"]
    for i, layer in enumerate(layers):
        c = colours[i % len(colours)]
        pts = [(s, p[layer]) for s, _, _, p in rows if layer in p]
        speeds = [s for s, _ in pts]
        axes[0].plot(speeds, [q[3] for _, q in pts], "o-", color=c, label=f"{layer} FEM")
        axes[0].plot(speeds, [q[1] for _, q in pts], "s--", color=c, mfc="none", label=f"{layer} real-time")
        axes[1].plot(speeds, [q[2] for _, q in pts], "o-", color=c, label=f"{layer} FEM")
        axes[1].plot(speeds, [q[0] for _, q in pts], "s--", color=c, mfc="none", label=f"{layer} real-time")
    for ax, ylabel in ((axes[0], "total force at the puncture (N)"), (axes[1], "puncture depth (mm)")):
        ax.set_xscale("log")
        ax.set_xlabel("insertion speed (mm/s); 3 and 20 held out")
        ax.set_ylabel(ylabel)
        for s in (3.0, 20.0):
            ax.axvline(s, color="0.85", lw=6, zorder=0)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7, ncol=2)
    fig.suptitle("Tuned preset against the FEM at 1, 3, 10, 20 mm/s (grey: speeds no calibration saw)", fontsize=10)
    fig.tight_layout()
    results_io.save_figure(fig, os.path.join(args.out_dir, "speed_law.png"))
    print("wrote", os.path.join(args.out_dir, "speed_law.md"), "and speed_law.png")


if __name__ == "__main__":
    main()
