"""puncture.calibrate: a small scene's known parameters recovered from the
model's own curve; the progress callback; a raising callback stopping it with
nothing written; bad input with the command line's message."""
import pytest

import puncture
from conftest import SOURCE_DIR, run_program

K = "layers/0/force_mesh/K_N_per_mm"
THRESHOLD = "layers/0/force_mesh/deformed_threshold_mm"


@pytest.fixture(scope="module")
def truth():
    return puncture.Scene.load(SOURCE_DIR / "tests" / "python" / "data" / "calibration_truth.json")


@pytest.fixture(scope="module")
def reference(truth):
    return puncture.Simulator(truth).run().curve()


def perturbed(truth):
    return truth.updated({K: truth.get(K) * 1.3, THRESHOLD: truth.get(THRESHOLD) * 1.2})


def test_calibration_recovers_the_skins_known_stiffness_and_threshold(truth, reference, tmp_path):
    seen = []
    result = puncture.calibrate(perturbed(truth), reference=reference, layers=["skin"], threads=2,
                                output_dir=tmp_path / "cal", progress=seen.append)
    tuned = result["preset"]
    assert tuned.get(K) == pytest.approx(truth.get(K), rel=0.03)
    assert tuned.get(THRESHOLD) == pytest.approx(truth.get(THRESHOLD), rel=0.03)
    assert tuned.get("layers/1/force_mesh/K_N_per_mm") == truth.get("layers/1/force_mesh/K_N_per_mm")
    assert tuned.name == "calibration_truth_tuned"
    assert len(seen) > 5 and seen[-1].evaluations == len(seen) and "skin" in seen[0].stage
    assert (tmp_path / "cal" / "calibration_truth_tuned.json").is_file()
    assert puncture.Scene.load(tmp_path / "cal" / "calibration_truth_tuned.json") == tuned
    provenance = result["calibration_truth_tuned.provenance"]
    assert provenance["optimiser"]["method"] == "levenberg_marquardt"
    curves = result["calibration_curves"]
    assert len(curves[next(iter(curves))]) > 100
    assert "calibration_summary" in result and result["output_dir"] == tmp_path / "cal"


def test_a_raising_progress_callback_stops_the_calibration_and_writes_nothing(truth, reference, tmp_path):
    class Enough(Exception):
        pass

    calls = []

    def stop_after_three(progress):
        calls.append(progress.evaluations)
        if len(calls) == 3:
            raise Enough("stop")

    with pytest.raises(Enough):
        puncture.calibrate(perturbed(truth), reference=reference, layers=["skin"], threads=2,
                           output_dir=tmp_path / "cal", progress=stop_after_three)
    assert len(calls) == 3  # never called again once it raised
    assert not (tmp_path / "cal").exists() or not any((tmp_path / "cal").iterdir())


def test_a_reference_without_force_is_bad_input_with_the_command_lines_message(truth, reference, program, tmp_path):
    columns = {"depth_mm": reference["depth_mm"], "time_s": reference["time_s"]}
    with pytest.raises(puncture.InputError) as raised:
        puncture.calibrate(truth, reference=columns)
    assert "force_N" in str(raised.value)
    path = tmp_path / "no_force.csv"
    path.write_text("depth_mm,time_s\n0.1,0.0\n0.2,0.1\n")
    scene_path = tmp_path / "truth.json"
    truth.save(scene_path)
    done = run_program(program, "calibrate", scene_path, "--reference", path, "-o", tmp_path / "out", "-q", check=False)
    assert done.returncode == 2
    from_file = pytest.raises(puncture.InputError, puncture.calibrate, truth, reference=path)
    assert done.stderr.strip().splitlines()[-1] == "error: " + str(from_file.value)
    assert not (tmp_path / "out").exists()


def test_an_unknown_option_is_a_type_error(truth, reference):
    with pytest.raises(TypeError, match="no_such_option"):
        puncture.calibrate(truth, reference=reference, no_such_option=1)


def test_a_bad_option_value_raises_with_the_command_lines_message(truth, reference):
    with pytest.raises(puncture.InputError, match="--bound-factor must be a finite number > 1"):
        puncture.calibrate(truth, reference=reference, bound_factor=0.5)


def test_ctrl_c_stops_the_calibration_and_writes_nothing(truth, reference, tmp_path):
    """SIGINT while the calibration runs in C++ (the GIL released, no progress callback):
    KeyboardInterrupt at the next model run, no output."""
    import os
    import signal
    import threading

    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            puncture.calibrate(perturbed(truth), reference=reference, layers=["skin", "fat"], threads=2,
                               tune_unidentifiable=True, output_dir=tmp_path / "cal")
    finally:
        timer.cancel()
    assert not (tmp_path / "cal").exists() or not any((tmp_path / "cal").iterdir())
