"""fem_study_run.py: one run of the FEM study driver (build target puncture_fem_study) for
the results/ scripts that run the FEM references on many scenes.

run_fem_study(binary, scene_path, out, keep, sectors=None, refinement=None):
    runs `binary run scene_path out [refinement]` (PUNCTURE_FEM_SECTORS=sectors for the 3D
    slab's cross-section), copies its fem_force_depth.csv, fem_summary.json and the scene
    (as scene.json) to the folder KEEP; returns (wall time in s, the summary as a dict,
    the force-depth CSV's rows as dicts). A failed run raises subprocess.CalledProcessError.
"""
import json
import os
import shutil
import subprocess
import time

import results_io


def run_fem_study(binary, scene_path, out, keep, sectors=None, refinement=None):
    env = dict(os.environ)
    if sectors is not None:
        env["PUNCTURE_FEM_SECTORS"] = str(sectors)
    command = [binary, "run", scene_path, out] + ([str(refinement)] if refinement is not None else [])
    t0 = time.monotonic()
    subprocess.run(command, env=env, check=True, stdout=subprocess.DEVNULL)
    wall = time.monotonic() - t0
    os.makedirs(keep, exist_ok=True)
    for name, source in (("fem_force_depth.csv", out), ("fem_summary.json", out), ("scene.json", None)):
        shutil.copyfile(os.path.join(out, name) if source else scene_path, os.path.join(keep, name))
    with open(os.path.join(out, "fem_summary.json")) as f:
        summary = json.load(f)
    return wall, summary, results_io.read_csv_rows(os.path.join(out, "fem_force_depth.csv"))
