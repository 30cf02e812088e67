"""Fixtures of the Python module's tests: the module, the `puncture` program
it is compared with, and small scenes made from the committed ones.

ctest sets PYTHONPATH (the module's build folder), PUNCTURE_PROGRAM and
PUNCTURE_SOURCE_DIR; run by hand from the source tree:
    PYTHONPATH=build/apps/python python3 -m pytest -q tests/python
"""
import os
import pathlib
import subprocess

import pytest

import puncture

SOURCE_DIR = pathlib.Path(os.environ.get("PUNCTURE_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))


@pytest.fixture(scope="session")
def source_dir():
    return SOURCE_DIR


@pytest.fixture(scope="session")
def program():
    """The `puncture` program built beside the module."""
    path = pathlib.Path(os.environ.get("PUNCTURE_PROGRAM", SOURCE_DIR / "build" / "apps" / "puncture"))
    assert path.is_file(), f"the puncture program is not built: {path}"
    return path


def run_program(program, *args, check=True):
    """Runs `puncture ARGS...`; returns the CompletedProcess (text)."""
    done = subprocess.run([str(program), *map(str, args)], capture_output=True, text=True, timeout=120)
    if check:
        assert done.returncode == 0, done.stderr
    return done


@pytest.fixture(scope="session")
def default_scene():
    return puncture.Scene.load(SOURCE_DIR / "scenes" / "default.json")


@pytest.fixture(scope="session")
def short_scene(default_scene):
    """The default slab inserted to 8 mm (the real-time model punctures the skin at 2.36 mm and the fat at
    6.38 mm, the muscle at 11.51 mm: results/default_run), a short dwell: about 2200 ticks."""
    return default_scene.updated({"name": "default_short", "insertion/target_depth_mm": 8.0, "insertion/dwell_s": 0.2})
