"""Self-test of the FEM records' checks (scripts/fem_robustness.py, check_run): a run folder
with a fem_force_depth.csv and a fem_summary.json written here; each contradiction the
checks name must be reported, a consistent run must pass.

Runs under pytest (python3 -m pytest -q tests/scripts/test_fem_robustness_checks.py) and on
its own without pytest, which is how ctest runs it (test scripts.fem_robustness_checks).
"""
import json
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import fem_robustness as fr  # noqa: E402

HEADER = ("time_s,depth_mm,velocity_mm_per_s,force_N,tip_force_N,cutting_force_N,friction_force_N,"
          "tip_stretch,phase,skin_state,fat_state")


def consistent_rows():
    """A skin pressed to 2.0 N at 3 mm, punctured there (drop to 1.0 N), cut on with friction;
    then the fat pressed. (depth mm, force N, cutting N, friction N, skin, fat)"""
    rows = []
    for k in range(31):
        d = 0.1 * k
        rows.append((d, 2.0 * d / 3.0, 0.0, 0.0, "pressed" if d > 0 else "untouched", "untouched"))
    for k in range(1, 11):
        d = 3.0 + 0.1 * k
        rows.append((d, 1.0 + 0.02 * k, 0.4, 0.05 * k, "punctured", "pressed"))
    return rows


def write_run(folder, rows, punctures):
    lines = [HEADER]
    for i, (d, f, cut, fric, skin, fat) in enumerate(rows):
        tip = f - fric - cut
        lines.append(f"{0.01 * i},{d},1,{f},{tip},{cut},{fric},1,insertion,{skin},{fat}")
    (folder / "fem_force_depth.csv").write_text("\n".join(lines) + "\n")
    (folder / "fem_summary.json").write_text(json.dumps({"punctures": [{"name": n} for n in punctures]}))
    return str(folder)


def test_a_consistent_run_passes(tmp_path):
    assert fr.check_run(write_run(tmp_path, consistent_rows(), ["skin"])) == []


def test_a_cutting_part_beyond_the_force_is_reported(tmp_path):
    rows = consistent_rows()
    d, f, _, fric, skin, fat = rows[33]
    rows[33] = (d, f, 12.0, fric, skin, fat)  # a crack run's dissipation per advance
    problems = fr.check_run(write_run(tmp_path, rows, ["skin"]))
    assert len(problems) == 1 and "cutting part 12" in problems[0], problems


def test_a_negative_cutting_part_is_reported(tmp_path):
    rows = consistent_rows()
    d, f, _, fric, skin, fat = rows[35]
    rows[35] = (d, f, -0.5, fric, skin, fat)
    problems = fr.check_run(write_run(tmp_path, rows, ["skin"]))
    assert len(problems) == 1 and "cutting part -0.5" in problems[0], problems


def test_friction_with_every_layer_intact_is_reported(tmp_path):
    rows = [(d, f, cut, fric, "pressed" if skin == "punctured" else skin, fat)
            for (d, f, cut, fric, skin, fat) in consistent_rows()]
    problems = fr.check_run(write_run(tmp_path, rows, []))
    assert any("shaft friction" in p for p in problems), problems


def test_a_drop_with_no_state_change_is_reported(tmp_path):
    rows = [(d, f, 0.0, 0.0, "pressed" if d > 0 else "untouched", "untouched")
            for (d, f, _, _, _, _) in consistent_rows()]
    problems = fr.check_run(write_run(tmp_path, rows, []))
    assert any("falls from 2 N" in p for p in problems), problems


def test_events_not_those_of_the_state_columns_are_reported(tmp_path):
    problems = fr.check_run(write_run(tmp_path, consistent_rows(), []))
    assert any("summary lists punctures" in p for p in problems), problems


if __name__ == "__main__":
    import selftest  # tests/scripts/, beside this file
    sys.exit(selftest.run(globals()))
