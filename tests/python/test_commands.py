"""puncture.fem and puncture.validate: the FEM reference read from the cache
the commands use (seeded here, so the test needs no FEM run), copied where
asked; bad input with the command line's message, nothing written."""
import json
import os
import signal

import numpy as np
import pytest

import puncture
from conftest import run_program
from synthetic_fem import seed_fem_reference


@pytest.fixture()
def seeded_cache(short_scene, tmp_path):
    """A cache entry of the short scene holding a known force-depth curve."""
    key = puncture.fem_cache_key(short_scene)
    entry = tmp_path / "cache" / key["hash"]
    entry.mkdir(parents=True)
    (entry / "fem_reference_key.json").write_text(key["key"])
    (entry / "fem_summary.json").write_text(json.dumps({"status": "ok", "punctures": [{"name": "skin", "depth_mm": 9.4}]}))
    depth = np.linspace(0.0, 12.0, 25)
    lines = ["# command: seeded by the test", "depth_mm,force_N"] + [f"{d!r},{0.25 * d!r}" for d in depth]
    (entry / "fem_force_depth.csv").write_text("\n".join(lines) + "\n")
    return tmp_path / "cache", key["hash"], depth


def test_fem_reads_the_cached_reference_and_copies_it_where_asked(short_scene, seeded_cache, tmp_path):
    cache, digest, depth = seeded_cache
    result = puncture.fem(short_scene, cache_dir=cache, output_dir=tmp_path / "copy")
    assert result["from_cache"] and result["hash"] == digest and result["dir"] == cache / digest
    np.testing.assert_array_equal(result["fem_force_depth"]["depth_mm"], depth)
    np.testing.assert_array_equal(result["fem_force_depth"]["force_N"], 0.25 * depth)
    assert result["fem_summary"]["punctures"][0]["name"] == "skin"
    assert sorted(p.name for p in (tmp_path / "copy").iterdir()) == sorted(result["files"])


def test_the_cache_key_follows_what_the_fem_reads(short_scene):
    key = puncture.fem_cache_key(short_scene)
    assert key == puncture.fem_cache_key(short_scene.updated({"realtime/haptic_rate_Hz": 2000}))  # real-time only
    assert key["hash"] != puncture.fem_cache_key(short_scene.updated({"layers/0/thickness_mm": 1.0}))["hash"]


def test_validate_with_a_missing_cases_file_gives_the_command_lines_message(short_scene, program, tmp_path):
    cases = tmp_path / "no_cases.json"
    with pytest.raises(puncture.InputError) as raised:
        puncture.validate(short_scene, cases=cases, output_dir=tmp_path / "report", cache_dir=tmp_path / "cache")
    assert str(cases) in str(raised.value)
    scene_path = tmp_path / "default_short.json"
    short_scene.save(scene_path)
    done = run_program(program, "validate", scene_path, "--cases", cases, "-o", tmp_path / "cli", "--cache",
                       tmp_path / "cache", "-q", check=False)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines()[-1] == "error: " + str(raised.value)
    assert not (tmp_path / "report").exists() and not (tmp_path / "cache").exists()


def test_validate_against_the_models_own_curve_equals_the_command_line(short_scene, program, tmp_path):
    """The FEM reference seeded with the model's own run: the pressing force RMSE is 0 and every
    puncture depth within one stored sample; the report's metrics are the command line's."""
    seed_fem_reference(short_scene, tmp_path / "cache")
    result = puncture.validate(short_scene, cache_dir=tmp_path / "cache", output_dir=tmp_path / "report")
    layers = result["validation_metrics"]["layers"]
    assert [m["layer"] for m in layers] == ["skin", "fat", "muscle"]
    for m in layers[:2]:  # punctured in the 8 mm insertion
        assert m["realtime_punctured"] and m["fem_punctured"]
        assert m["pressing_force_rmse_relative"] == 0.0
        assert abs(m["puncture_depth_error_mm"]) <= 0.1  # 10 ticks at 10 mm/s
    np.testing.assert_array_equal(result["layer_metrics"]["pressing_force_rmse_N"][:2], [0.0, 0.0])
    assert sorted(result["files"]) == sorted(str(p.relative_to(tmp_path / "report"))
                                             for p in (tmp_path / "report").rglob("*") if p.is_file())
    np.testing.assert_array_equal(result["realtime_curve"]["force_N"][::10][:50],
                                  puncture.Simulator(short_scene).run().force_N[::10][:50])
    scene_path = tmp_path / "default_short.json"
    short_scene.save(scene_path)
    run_program(program, "validate", scene_path, "-o", tmp_path / "cli", "--cache", tmp_path / "cache", "--no-vtk", "-q")
    cli = json.loads((tmp_path / "cli" / "validation_metrics.json").read_text())
    assert cli["layers"] == layers and cli["acceptance"] == result["validation_metrics"]["acceptance"]


def test_fem_computes_a_missing_reference_into_the_cache_or_says_why_not(short_scene, tmp_path):
    """With the FEM built: a 1.5 mm press computed in this process (a few seconds), then read from the
    cache; without it: the command line's RunError, nothing cached."""
    scene = short_scene.updated({"insertion/target_depth_mm": 1.5, "insertion/dwell_s": 0.0})
    if not puncture.HAVE_FEM:
        with pytest.raises(puncture.RunError, match="this build has no FEM"):
            puncture.fem(scene, cache_dir=tmp_path / "cache")
        assert not (tmp_path / "cache").exists()
        return
    fractions = []
    first = puncture.fem(scene, cache_dir=tmp_path / "cache", progress=fractions.append)
    assert len(fractions) >= 3 and np.all(np.diff(fractions) > 0.0) and fractions[-1] == pytest.approx(1.0)
    force = first["fem_force_depth"]["force_N"]
    assert not first["from_cache"] and first["fem_summary"].get("status") != "failed"
    assert np.all(np.isfinite(force)) and force.max() > 0.0
    again = puncture.fem(scene, cache_dir=tmp_path / "cache")
    assert again["from_cache"] and again["dir"] == first["dir"]
    np.testing.assert_array_equal(again["fem_force_depth"]["force_N"], force)


def test_ctrl_c_stops_the_fem_at_its_next_load_step_and_caches_nothing(short_scene, tmp_path):
    """SIGINT sent from the progress callback (as a user's Ctrl-C arrives while the FEM runs): the call
    raises KeyboardInterrupt after that step, no further step is solved, the cache holds nothing."""
    scene = short_scene.updated({"insertion/target_depth_mm": 1.5, "insertion/dwell_s": 0.0})
    if not puncture.HAVE_FEM:
        with pytest.raises(puncture.RunError, match="this build has no FEM"):
            puncture.fem(scene, cache_dir=tmp_path / "cache", progress=lambda f: None)
        return
    fractions = []

    def progress(fraction):
        fractions.append(fraction)
        if len(fractions) == 2:
            os.kill(os.getpid(), signal.SIGINT)

    # Python's own Ctrl-C handler, also where the test runner was started with SIGINT ignored.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            puncture.fem(scene, cache_dir=tmp_path / "cache", progress=progress)
    finally:
        signal.signal(signal.SIGINT, previous)
    assert len(fractions) == 2 and 0.0 < fractions[0] < fractions[1] < 1.0
    assert list((tmp_path / "cache").glob("*")) == []


def test_validate_against_a_recording_of_the_model_itself(short_scene, tmp_path):
    """validate(references=[...]): the scene's model judged against a recording (here its own run, written as a
    measured curve with its speed): its force RMSE is about 0 and the skin's puncture is where the recording's is."""
    run = puncture.Simulator(short_scene).run()
    lines = ["# speed_mm_per_s: 10", "time_s,depth_mm,force_N"]
    for t, d, f in zip(run.time_s[::10], run.depth_mm[::10], run.force_N[::10]):
        lines.append(f"{t!r},{d!r},{f!r}")
    recording = tmp_path / "own_run.csv"
    recording.write_text("\n".join(lines) + "\n")
    result = puncture.validate(short_scene, references=[recording], output_dir=tmp_path / "report")
    entry = result["recordings_validation"]["recordings"][0]
    assert entry["recording"] == str(recording)
    assert entry["force_rmse_relative"] < 0.02
    skin = entry["layers"][0]
    assert skin["recording_punctured"] and skin["model_punctured"]
    assert abs(skin["model"]["depth_mm"] - skin["recording"]["depth_mm"]) <= 0.2
    assert (tmp_path / "report" / "recording_curves.csv").is_file()
