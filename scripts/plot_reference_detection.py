#!/usr/bin/python3
"""What `puncture calibrate --reference` found on its reference, to check before trusting the fit
(matplotlib; run with /usr/bin/python3).

Usage: plot_reference_detection.py DIR [--out PNG]

In:  DIR/calibration_curves.csv     the reference curve as calibrated (curve = measured or fem;
                                     time_s, depth_mm from contact, force_N tared, phase)
     DIR/<name>.provenance.json     references[0]: metadata (a raw recording's format, tare_N,
                                     noise_N, contact_time_s, contact_<position column>,
                                     speed_mm_per_s) and reference_punctures (every force drop
                                     with its size and whether it is marginal, the punctures
                                     kept per layer, the contact onset, the noise, the doubts);
     (the calibration's command line: the "# command:" line of calibration_curves.csv)
Out: DIR/reference_detection.png (or --out): top, force against depth from contact (insertion
     solid, hold and withdrawal grey), the contact (depth 0 of a raw recording, or the contact
     onset), every force drop (marginal ones grey) and the punctures kept, with the layer's name,
     depth (mm) and force (N); bottom, force against time with the phases shaded (approach,
     insertion, hold, withdrawal). The figure's foot names the calibration's command, this
     script's command, the machine, the git revision and the date (scripts/provenance.py).
Exit 1 with a message naming the file when an input is missing or malformed.
"""
import csv
import glob
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import provenance  # noqa: E402  (scripts/, beside this file)
import results_io  # noqa: E402

PHASE_COLOURS = {"approach": "#dddddd", "insertion": "#d8e8f8", "dwell": "#f8ecd0", "withdrawal": "#e0f0d8"}


def fail(message):
    print(f"error: {message}", file=sys.stderr)
    sys.exit(1)


def read_reference(folder):
    """The first reference's samples (time_s, depth_mm, force_N, phase) from calibration_curves.csv."""
    path = os.path.join(folder, "calibration_curves.csv")
    if not os.path.exists(path):
        fail(f"{path}: missing (run puncture calibrate --reference ... -o {folder} first)")
    rows = {"time_s": [], "depth_mm": [], "force_N": [], "phase": [], "command": "unknown"}
    with open(path, newline="") as f:
        lines = f.readlines()
    for line in lines:
        if line.startswith("# command:"):
            rows["command"] = line.split(":", 1)[1].strip()
    for line_no, row in enumerate(csv.DictReader(l for l in lines if not l.startswith("#")), start=2):
        if row.get("curve") not in ("measured", "fem"):
            continue
        try:
            for key in ("time_s", "depth_mm", "force_N"):
                rows[key].append(float(row[key]))
        except (KeyError, TypeError, ValueError):
            fail(f"{path}: data row {line_no}: column time_s, depth_mm or force_N missing or not a number")
        rows["phase"].append(row.get("phase") or "insertion")
    if not rows["depth_mm"]:
        fail(f"{path}: no reference rows (curve 'measured' or 'fem')")
    return rows


def read_provenance(folder):
    files = sorted(glob.glob(os.path.join(folder, "*.provenance.json")))
    if not files:
        fail(f"{folder}: no <name>.provenance.json (the tuned preset's provenance)")
    try:
        with open(files[0]) as f:
            j = json.load(f)
        ref = j["references"][0]
        return ref, ref.get("reference_punctures", {})
    except (OSError, ValueError, KeyError, IndexError) as e:
        fail(f"{files[0]}: cannot read references[0] ({e})")


def phase_spans(ref):
    """(phase, first index, last index) runs; insertion samples before contact are the approach."""
    names = ["approach" if p == "insertion" and d < 0.0 else p for p, d in zip(ref["phase"], ref["depth_mm"])]
    spans, start = [], 0
    for i in range(1, len(names) + 1):
        if i == len(names) or names[i] != names[start]:
            spans.append((names[start], start, i - 1))
            start = i
    return spans


def force_depth_panel(ax, ref, events, meta):
    inserting = [i for i, p in enumerate(ref["phase"]) if p == "insertion"]
    other = [i for i, p in enumerate(ref["phase"]) if p != "insertion"]
    ax.plot([ref["depth_mm"][i] for i in other], [ref["force_N"][i] for i in other], ".", color="0.7", ms=2,
            label="hold and withdrawal")
    ax.plot([ref["depth_mm"][i] for i in inserting], [ref["force_N"][i] for i in inserting], "-", color="C0", lw=1,
            label="insertion")
    contact = 0.0 if "tare_N" in meta else events.get("contact_onset_mm")
    if contact is not None:
        what = (f"contact (fit): t = {float(meta['contact_time_s']):.3f} s, tare {float(meta['tare_N']):.3f} N"
                if "tare_N" in meta else "contact onset")
        ax.axvline(contact, color="C2", ls="--", lw=1, label=what)
    for d in events.get("force_drops", []):
        ax.axvline(d["depth_mm"], color="0.6" if d.get("marginal") else "C3", ls=":", lw=1)
    for p in events.get("punctures", []):
        if p.get("found"):
            ax.plot(p["depth_mm"], p["force_N"], "v", color="C3", ms=8)
            ax.annotate(f"{p['layer']}: {p['depth_mm']:.2f} mm, {p['force_N']:.2f} N", (p["depth_mm"], p["force_N"]),
                        textcoords="offset points", xytext=(6, 6), fontsize=9, color="C3")
    ax.plot([], [], ":", color="C3", label="force drop")
    ax.plot([], [], ":", color="0.6", label="marginal drop")
    ax.set_xlabel("depth from contact (mm)")
    ax.set_ylabel("force (N)")
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3)


def force_time_panel(ax, ref):
    for name, a, b in phase_spans(ref):
        ax.axvspan(ref["time_s"][a], ref["time_s"][b], color=PHASE_COLOURS.get(name, "#eeeeee"), lw=0)
    ax.plot(ref["time_s"], ref["force_N"], "-", color="C0", lw=0.8)
    for name, colour in PHASE_COLOURS.items():
        ax.fill_between([], [], color=colour, label={"dwell": "hold"}.get(name, name))
    ax.set_xlabel("time (s)")
    ax.set_ylabel("force (N)")
    ax.legend(fontsize=8, loc="upper right", ncol=4)
    ax.grid(alpha=0.3)


def main(argv):
    args = [a for a in argv[1:] if a != "--out"]
    if len(args) < 1 or (("--out" in argv) and len(args) < 2):
        fail("usage: plot_reference_detection.py DIR [--out PNG]")
    folder = args[0]
    out = args[1] if "--out" in argv else os.path.join(folder, "reference_detection.png")
    ref = read_reference(folder)
    summary, events = read_provenance(folder)
    command = ref["command"]
    meta = summary.get("metadata", {})
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 8), gridspec_kw={"height_ratios": [3, 2]})
    force_depth_panel(top, ref, events, meta)
    force_time_panel(bottom, ref)
    noise = events.get("noise_N")
    doubts = events.get("doubts") or []
    top.set_title(f"What was found on {summary.get('source', '?')}\n{events.get('source', '?')}"
                  + (f", noise {noise:.3g} N" if noise is not None else "")
                  + (f"; DOUBTS: {'; '.join(doubts)}" if doubts else ""), fontsize=9)
    foot = (f"calibration: {command}\nplot: {' '.join(os.path.basename(a) if i == 0 else a for i, a in enumerate(argv))}\n"
            f"machine: {provenance.machine()}; git {provenance.git_revision()}; {provenance.utc_now()} UTC")
    fig.text(0.01, 0.005, foot, fontsize=6, va="bottom", family="monospace", wrap=True)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    results_io.save_figure(fig, out)
    print(out)


if __name__ == "__main__":
    main(sys.argv)
