"""A synthetic FEM reference of a scene seeded into a cache folder, so that
fem() and validate() run in the tests without the FEM (and in builds without
it): the real-time model's own run stands as the FEM's force curve (every
10th tick; states from the model), its punctures as the FEM's, and made-up
Gaussian-like tents as the surface and spring-back profiles. Only the
plumbing is under test here, not the FEM."""
import json
import math
import pathlib

import puncture

CURVE_COLUMNS = ["time_s", "depth_mm", "velocity_mm_per_s", "force_N", "tip_force_N", "cutting_force_N",
                 "friction_force_N"]


def tent_rows(prefix, depth_mm):
    return [f"{prefix},{depth_mm!r},{r!r},{-depth_mm * math.exp(-r / 2.0)!r}" for r in (0.0, 1.0, 2.0, 4.0, 8.0)]


def write_curve(entry, run):
    curve = run.curve()
    states = [f"{layer}_state" for layer in run.layer_names]
    lines = [",".join(CURVE_COLUMNS + ["phase"] + states)]
    for i in range(0, len(run), 10):
        numbers = [repr(float(curve[c][i])) for c in CURVE_COLUMNS]
        lines.append(",".join(numbers + [str(curve["phase"][i])] + [str(curve[s][i]) for s in states]))
    (entry / "fem_force_depth.csv").write_text("# command: synthetic FEM reference (tests/python)\n" + "\n".join(lines) + "\n")


def seed_fem_reference(scene, cache_dir):
    """Writes the entry under the scene's cache key; returns (its folder, the run it was made from)."""
    key = puncture.fem_cache_key(scene)
    entry = pathlib.Path(cache_dir) / key["hash"]
    entry.mkdir(parents=True)
    (entry / "fem_reference_key.json").write_text(key["key"])
    run = puncture.Simulator(scene).run()
    write_curve(entry, run)
    punctures = [{"name": e.layer_name, "depth_mm": e.depth_mm, "force_N": e.total_force_N} for e in run.events]
    (entry / "fem_summary.json").write_text(json.dumps({"status": "ok", "punctures": punctures}))
    profile = ["step,depth_mm,r_mm,uz_mm,surface"]
    for step, depth in enumerate((0.5, 1.0, 1.5, 2.0)):
        profile += [row + f",{run.layer_names[0]}" for row in tent_rows(step, depth)]
    (entry / "fem_surface_profile.csv").write_text("\n".join(profile) + "\n")
    recovery = ["layer,phase,depth_mm,r_mm,uz_mm"]
    for event in run.events:
        for phase in ("before", "after"):
            recovery += [f"{event.layer},{phase}," + row.split(",", 1)[1] for row in tent_rows(0, event.depth_mm)]
    (entry / "fem_recovery_profile.csv").write_text("\n".join(recovery) + "\n")
    return entry, run
