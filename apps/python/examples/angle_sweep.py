#!/usr/bin/env python3
"""The needle at an angle: the default slab inserted at several angles to the
surface normal (insertion/angle_deg), the force along the needle and across it
against the depth along the needle in one plot, and per angle the skin's
puncture: depth along the needle, the normal load, the force along and across.

    PYTHONPATH=build/apps/python python3 apps/python/examples/angle_sweep.py --out out/angle_sweep.png

The model's tip is frictionless (core/README.md, "The needle at an angle"): the
skin breaks under the same normal load at every angle, felt as F cos a along
the needle and F sin a across it. The FEM reference is axial only, so nothing
here is validated at an angle yet.
"""
import argparse
import math
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import puncture  # noqa: E402


def sweep(scene, angles):
    """{angle: RunResult} of the scene inserted at each angle (deg)."""
    return {a: puncture.Simulator(scene.updated({"insertion/angle_deg": a})).run() for a in angles}


def skin_break(r):
    """(depth along the needle mm, normal load N, force along N at the break; on the tick before: the force
    across N and the skin's load N) or None."""
    skin = [e for e in r.events if e.layer_name == "skin"]
    if not skin:
        return None
    i = int(np.searchsorted(r.time_s, skin[0].time_s))
    before = max(i - 1, 0)
    return (r.path_depth_mm[i], skin[0].surface_force_N, skin[0].total_force_N, r.lateral_force_N[before],
            r.layer_surface_force_N[before, 0])


def plot(runs, path):
    fig, (along, across) = plt.subplots(1, 2, figsize=(11, 4.2), sharex=True)
    for a, r in runs.items():
        inserting = r.phase == r.phase_names.index("insertion")
        along.plot(r.path_depth_mm[inserting], r.force_N[inserting], label=f"{a:g} deg")
        across.plot(r.path_depth_mm[inserting], r.lateral_force_N[inserting], label=f"{a:g} deg")
    along.set(xlabel="tip depth along the needle (mm)", ylabel="force along the needle (N)")
    across.set(xlabel="tip depth along the needle (mm)", ylabel="force across the needle (N)")
    along.legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=str(puncture.default_scene_path()))
    parser.add_argument("--angles", default="0,15,30", help="angles to the surface normal, deg (the scene's sample "
                        "must hold the inclined path: the reader refuses one that leaves it)")
    parser.add_argument("--depth-mm", type=float, default=12.0, help="target depth of each insertion (vertical)")
    parser.add_argument("--out", default="out/angle_sweep.png", help="the plot (PNG)")
    args = parser.parse_args(argv)
    scene = puncture.Scene.load(args.scene).updated({"insertion/target_depth_mm": args.depth_mm, "insertion/dwell_s": 0.1})
    runs = sweep(scene, [float(a) for a in args.angles.split(",")])
    print("| angle (deg) | skin punctured at, along the needle (mm) | normal load (N) | along the needle (N) "
          "| across, tick before (N) | across / (its load sin a) |\n|---|---|---|---|---|---|")
    for a, r in runs.items():
        b = skin_break(r)
        if b is None:
            print(f"| {a:g} | not punctured | - | - | - | - |")
            continue
        ratio = b[3] / (b[4] * math.sin(math.radians(a))) if a > 0 else float("nan")
        print(f"| {a:g} | {b[0]:.2f} | {b[1]:.3f} | {b[2]:.3f} | {b[3]:.3f} | {ratio:.3f} |")
    plot(runs, pathlib.Path(args.out))
    print(f"plot: {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
