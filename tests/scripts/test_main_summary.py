"""Self-test of scripts/main_summary.py (what `bash scripts/main.sh` prints after its run): a
run folder and a validation folder written here; the table must put the run's puncture depth
beside the FEM's with the error, flag a run whose depths differ from the validated ones, and
stop naming a missing file.

Runs under pytest and on its own without pytest (ctest scripts.main_summary).
"""
import json
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "main_summary.py"

METRICS = """# command: puncture validate preset.json -o v
# git_revision: abc1234
# date_utc: 2026-01-01T00:00:00Z
layer,fem_puncture_depth_mm,realtime_puncture_depth_mm,fem_puncture_force_N,realtime_puncture_force_N
skin,9.8,9.76,2.94,2.834
fat,10,10.01,2.479,2.711
"""


def run(tmp, skin_depth_mm):
    (tmp / "run").mkdir(exist_ok=True)
    (tmp / "v").mkdir(exist_ok=True)
    events = [{"layer": "skin", "depth_mm": skin_depth_mm, "total_force_N": 2.8},
              {"layer": "fat", "depth_mm": 10.01, "total_force_N": 1.6}]
    (tmp / "run" / "summary.json").write_text(json.dumps({"puncture_events": events}))
    (tmp / "v" / "layer_metrics.csv").write_text(METRICS)
    return subprocess.run([sys.executable, str(SCRIPT), str(tmp / "run"), "--validation", str(tmp / "v")],
                          capture_output=True, text=True)


def test_the_runs_depths_beside_the_fems(tmp_path):
    p = run(tmp_path, 9.76)
    assert p.returncode == 0, p.stderr
    skin = next(l for l in p.stdout.splitlines() if l.startswith("skin"))
    assert skin.split()[1:4] == ["9.76", "9.80", "-0.04"], skin
    assert "-3.6%" in skin, skin
    assert "git abc1234" in p.stdout and "stale" not in p.stdout


def test_a_run_that_punctures_elsewhere_says_the_validation_is_stale(tmp_path):
    p = run(tmp_path, 9.30)
    assert p.returncode == 0, p.stderr
    assert "punctures skin elsewhere" in p.stdout and "stale" in p.stdout, p.stdout


def test_a_missing_input_is_named(tmp_path):
    p = subprocess.run([sys.executable, str(SCRIPT), str(tmp_path / "nowhere")], capture_output=True, text=True)
    assert p.returncode != 0
    assert "summary.json: missing" in p.stderr, p.stderr


if __name__ == "__main__":
    import selftest  # tests/scripts/, beside this file
    sys.exit(selftest.run(globals()))
