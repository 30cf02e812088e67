#!/usr/bin/env python3
"""A parameter sweep: the skin's virtual stiffness K (force mesh, N/mm) over a
range, the default slab inserted to 12 mm each time; the force-depth curves
in one plot and the skin's puncture depth and force per K in a table.

    PYTHONPATH=build/apps/python python3 apps/python/examples/parameter_sweep.py --out out/sweep_K.png

Start from here for any field of the scene: Scene.updated({json path: value}).
"""
import argparse
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import puncture  # noqa: E402

FIELD = "layers/0/force_mesh/K_N_per_mm"


def sweep(scene, values):
    """{value: RunResult} of the scene with FIELD set to each value."""
    return {k: puncture.Simulator(scene.updated({FIELD: k})).run() for k in values}


def plot(runs, path):
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for k, r in runs.items():
        inserting = r.phase == r.phase_names.index("insertion")
        ax.plot(r.depth_mm[inserting], r.force_N[inserting], label=f"K = {k:g} N/mm")
    ax.set_xlabel("tip depth (mm)")
    ax.set_ylabel("needle force (N)")
    ax.set_title("Skin stiffness K of the force mesh, default slab")
    ax.legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=str(puncture.default_scene_path()))
    parser.add_argument("--values", default="0.08,0.12,0.16,0.24,0.32", help="K values, N/mm")
    parser.add_argument("--depth-mm", type=float, default=12.0, help="target depth of each insertion")
    parser.add_argument("--out", default="out/parameter_sweep.png", help="the plot (PNG)")
    args = parser.parse_args(argv)
    scene = puncture.Scene.load(args.scene).updated({"insertion/target_depth_mm": args.depth_mm, "insertion/dwell_s": 0.1})
    runs = sweep(scene, [float(v) for v in args.values.split(",")])
    print("| K (N/mm) | skin punctured at (mm) | under (N) | peak force (N) |\n|---|---|---|---|")
    for k, r in runs.items():
        skin = [e for e in r.events if e.layer_name == "skin"]
        at = f"{skin[0].depth_mm:.2f} | {skin[0].total_force_N:.3f}" if skin else "not punctured | -"
        print(f"| {k:g} | {at} | {r.force_N.max():.3f} |")
    plot(runs, pathlib.Path(args.out))
    print(f"plot: {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
