"""The examples of apps/python/examples run as a researcher runs them, on
short settings, and make their outputs."""
import os
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR

EXAMPLES = SOURCE_DIR / "apps" / "python" / "examples"


def run_example(name, *args):
    env = dict(os.environ, MPLBACKEND="Agg")
    done = subprocess.run([sys.executable, str(EXAMPLES / name), *map(str, args)], capture_output=True, text=True,
                          timeout=120, env=env)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_parameter_sweep_makes_its_plot_and_table(tmp_path):
    plot = tmp_path / "sweep.png"
    out = run_example("parameter_sweep.py", "--values", "0.12,0.24", "--depth-mm", "10.5", "--out", plot)
    assert plot.stat().st_size > 10_000 and plot.read_bytes()[:4] == b"\x89PNG"
    rows = [line for line in out.splitlines() if line.startswith("| 0.")]
    assert len(rows) == 2 and all("not punctured" not in r for r in rows)
    # A stiffer skin mesh reaches the critical deflection under more force.
    force = [float(r.split("|")[3]) for r in rows]
    assert force[1] > force[0]


def test_closed_loop_controller_presses_until_the_skin_breaks():
    out = run_example("closed_loop_press.py")
    assert "skin broke at tick" in out
    broke = out.splitlines()[0]
    depth_mm = float(broke.split("depth ")[1].split(" mm")[0])
    assert 1.0 < depth_mm < 5.0  # the default skin breaks at 2.36 mm under the scripted insertion (results/default_run)
    assert "holding the tip there" in out


def test_angle_sweep_resolves_the_skins_load_along_and_across_the_needle(tmp_path):
    plot = tmp_path / "angles.png"
    out = run_example("angle_sweep.py", "--angles", "0,30", "--depth-mm", "4", "--out", plot)
    assert plot.stat().st_size > 10_000 and plot.read_bytes()[:4] == b"\x89PNG"
    rows = {r.split("|")[1].strip(): [c.strip() for c in r.split("|")[2:-1]]
            for r in out.splitlines() if r.startswith("| 0 ") or r.startswith("| 30 ")}
    assert set(rows) == {"0", "30"}
    # The same normal load breaks the skin; along the needle it is felt times cos 30, across it times sin 30.
    assert float(rows["30"][1]) == pytest.approx(float(rows["0"][1]), rel=0.02)
    assert float(rows["30"][4]) == pytest.approx(1.0, abs=0.01)
    assert float(rows["30"][0]) > float(rows["0"][0])  # deeper along the needle
