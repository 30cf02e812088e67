"""puncture.compare: `puncture compare` called from Python against a FEM
reference seeded into the cache (the real-time model's own run, so no FEM
runs here): the same table as the command line's, the reference itself
graded with no error, and bad input raising the command line's message with
nothing written."""
import csv
import json
import os
import signal
import threading
import time

import numpy as np
import pytest

import puncture
from conftest import run_program
from synthetic_fem import seed_fem_reference

MODELS = ["realtime", "shf", "fem"]
# Columns of comparison.csv that measure the machine, not the model.
TIMING = {"memory_MB", "step_time_mean_ms", "step_time_p99_ms", "step_time_max_ms", "build_s", "run_s"}


@pytest.fixture(scope="module")
def compared(short_scene, program, tmp_path_factory):
    """compare() and `puncture compare` on the short scene, same options, one seeded cache."""
    tmp = tmp_path_factory.mktemp("compare")
    seed_fem_reference(short_scene, tmp / "cache")
    result = puncture.compare(short_scene, models=MODELS, scene_parameters=True, cache_dir=tmp / "cache",
                              output_dir=tmp / "py")
    scene_path = tmp / "default_short.json"
    short_scene.save(scene_path)
    run_program(program, "compare", scene_path, "--models", ",".join(MODELS), "--scene-parameters", "--frames", "0",
                "--no-vtk", "--cache", tmp / "cache", "-o", tmp / "cli", "-q")
    return result, tmp


def test_compare_returns_the_command_lines_table(compared):
    result, tmp = compared
    table = result["comparison"]
    assert list(table["model"]) == MODELS
    lines = [l for l in (tmp / "cli" / "comparison.csv").read_text().splitlines() if l and not l.startswith("#")]
    rows = list(csv.DictReader(lines))
    cli = {name: [r[name] for r in rows] for name in rows[0]}
    assert sorted(table.keys()) == sorted(cli.keys())
    assert np.asarray(table["build_s"]).dtype.kind == "f", "a numeric column with NaN rows stays numeric"
    for name, values in cli.items():
        if name == "model" or name in TIMING:
            continue
        mine = np.asarray(table[name])
        if mine.dtype.kind in "fi":
            np.testing.assert_allclose(mine, [float(v) for v in values], rtol=1e-12, atol=0.0, equal_nan=True,
                                       err_msg=name)
        else:
            assert [str(v) for v in mine] == values, name
    summary = json.loads((tmp / "cli" / "comparison_summary.json").read_text())
    assert sorted(result["comparison_summary"].keys()) == sorted(summary.keys())
    assert result["output_dir"] == tmp / "py"
    assert sorted(result["files"]) == sorted(str(p.relative_to(tmp / "py")) for p in (tmp / "py").rglob("*")
                                             if p.is_file())


def test_the_reference_grades_itself_without_error_and_the_models_with_some(compared):
    result, _ = compared
    table = result["comparison"]
    rmse = dict(zip(table["model"], np.asarray(table["force_rmse_relative"], dtype=float)))
    assert rmse["fem"] == 0.0
    # The seeded reference is the real-time model's own run (every 10th tick):
    # the model meets it at every sample; the SH-only model (the layer surfaces
    # without their force mesh, quasi-static) does not.
    assert rmse["realtime"] <= 1e-9
    assert rmse["shf"] > 0.05


def test_compare_with_an_unknown_model_raises_the_command_lines_message(short_scene, program, tmp_path):
    with pytest.raises(puncture.InputError) as raised:
        puncture.compare(short_scene, models=["no_such_model"], cache_dir=tmp_path / "cache",
                         output_dir=tmp_path / "out")
    assert "no_such_model" in str(raised.value)
    scene_path = tmp_path / "default_short.json"
    short_scene.save(scene_path)
    done = run_program(program, "compare", scene_path, "--models", "no_such_model", "--cache", tmp_path / "cache",
                       "-o", tmp_path / "cli", "-q", check=False)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines()[-1] == "error: " + str(raised.value)
    assert not (tmp_path / "out").exists() and not (tmp_path / "cli").exists()


def test_ctrl_c_stops_compare_during_a_model_run_writing_nothing(short_scene, tmp_path):
    """SIGINT 2 s into a comparison of the volumetric mass-spring model (about 25 s to run): the call raises
    KeyboardInterrupt well before the run could have ended, and no output folder is left."""
    seed_fem_reference(short_scene, tmp_path / "cache")
    timer = threading.Timer(2.0, os.kill, (os.getpid(), signal.SIGINT))
    # Python's own Ctrl-C handler, also where the test runner was started with SIGINT ignored.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            puncture.compare(short_scene, models=["msm"], scene_parameters=True, cache_dir=tmp_path / "cache",
                             frames=0, write_vtk=False, output_dir=tmp_path / "out")
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    assert time.monotonic() - start < 10.0
    assert not (tmp_path / "out").exists()
