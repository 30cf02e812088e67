"""puncture.Simulator: run() against `puncture run`'s CSV, ticking by hand
against run(), the tick's defaults and errors, the arrays for plotting."""
import csv
import json

import numpy as np
import pytest

import puncture
from conftest import run_program


def read_program_curve(path):
    """realtime_curve.csv of `puncture run`: {column: list of str}, '#' lines skipped."""
    with open(path, newline="") as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    header, body = rows[0], rows[1:]
    return {name: [r[i] for r in body] for i, name in enumerate(header)}


@pytest.fixture(scope="module")
def short_run(short_scene):
    return puncture.Simulator(short_scene).run()


def test_run_equals_the_programs_csv_column_by_column(short_scene, short_run, program, tmp_path):
    scene_path = tmp_path / "default_short.json"
    short_scene.save(scene_path)
    run_program(program, "run", scene_path, "-o", tmp_path / "out", "--no-frames", "-q")
    csv_columns = read_program_curve(tmp_path / "out" / "realtime_curve.csv")
    r = short_run
    assert len(csv_columns["time_s"]) == len(r) > 2000
    for name in ["time_s", "depth_mm", "velocity_mm_per_s", "force_N", "tip_force_N", "cutting_force_N",
                 "friction_force_N"]:
        np.testing.assert_array_equal(np.array(csv_columns[name], dtype=float), r[name], err_msg=name)
    assert list(np.array(r.phase_names)[r.phase]) == csv_columns["phase"]
    for k, layer in enumerate(r.layer_names):
        assert list(np.array(r.state_names)[r.layer_state[:, k]]) == csv_columns[f"{layer}_state"]
        for part in ["surface_force_N", "cutting_force_N", "friction_force_N", "damping_force_N"]:
            np.testing.assert_array_equal(np.array(csv_columns[f"{layer}_{part}"], dtype=float),
                                          r[f"layer_{part}"][:, k], err_msg=f"{layer}_{part}")
        np.testing.assert_array_equal(np.array(csv_columns[f"{layer}_deformed_rings"], dtype=int),
                                      r.layer_deformed_rings[:, k])
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert [(e.layer_name, e.depth_mm, e.total_force_N) for e in r.events] == \
        [(e["layer"], e["depth_mm"], e["total_force_N"]) for e in summary["puncture_events"]]


def test_run_punctures_skin_and_fat_and_its_parts_sum_to_the_force(short_run):
    r = short_run
    assert [e.layer_name for e in r.events] == ["skin", "fat"]
    np.testing.assert_allclose(r.tip_force_N + r.cutting_force_N + r.friction_force_N, r.force_N, atol=1e-12)
    assert r.layer_state.shape == (len(r), 3) and r.layer_state.dtype == np.int8
    assert r.force_N.max() > 1.0 and np.all(np.isfinite(r.force_N))
    skin = r.layer("skin")
    assert skin["state"][-1] == r.state_names.index("punctured")
    assert r.time_step_s == pytest.approx(1e-3)


def test_ticking_by_hand_reproduces_run(short_scene, short_run):
    r = short_run
    sim = puncture.Simulator(short_scene)
    force = np.empty(len(r))
    events = []
    for i in range(len(r)):
        tick = sim.tick(r.depth_mm[i], velocity_mm_per_s=r.velocity_mm_per_s[i], time_s=r.time_s[i])
        force[i] = tick.force_N
        events += tick.events
    np.testing.assert_allclose(force, r.force_N, rtol=1e-9, atol=1e-12)
    assert [(e.layer_name, e.time_s) for e in events] == [(e.layer_name, e.time_s) for e in r.events]
    assert sim.layer_states == {"skin": "punctured", "fat": "punctured", "muscle": "untouched"}
    assert sim.ticks == len(r)


def test_tick_defaults_time_and_velocity_from_the_last_tick(short_scene):
    sim = puncture.Simulator(short_scene)
    first = sim.tick(-1.0)
    second = sim.tick(-0.99)
    assert (first.time_s, first.velocity_mm_per_s) == (0.0, 0.0)
    assert second.time_s == pytest.approx(sim.time_step_s)
    assert second.velocity_mm_per_s == pytest.approx(0.01 / sim.time_step_s)
    assert second.force_N == 0.0 and second.layer_states["skin"] == "untouched"


def test_a_pressed_skin_pushes_back_along_the_needle(short_scene):
    sim = puncture.Simulator(short_scene)
    for i in range(200):  # to 2 mm at 10 mm/s: the skin breaks at 2.36 mm
        tick = sim.tick(i * 0.01, velocity_mm_per_s=10.0)
    assert tick.layer_states["skin"] == "pressed" and tick.force_N > 0.0
    # Along the axis (the SH surface's normal there is vertical to rounding).
    np.testing.assert_allclose(tick.force_vector_N, [0.0, 0.0, tick.force_N], atol=1e-12)
    assert tick.lateral_force_N < 1e-12
    assert tick.layers[0].surface_force_N == pytest.approx(tick.surface_force_N)
    nodes, rest = sim.force_mesh_nodes_mm("skin"), sim.force_mesh_nodes_mm(0, rest=True)
    assert nodes.shape == rest.shape and nodes.shape[1] == 3
    assert nodes[:, 2].min() < rest[:, 2].min() - 1.0  # the tent under the tip (about 2 mm), mm
    assert len(sim.force_mesh_rings("skin")) == len(nodes)
    surface = sim.layer_surface_mm("skin", n_polar=9, n_azimuth=12)
    assert surface.shape == (9, 12, 3)
    assert surface[0, 0, 2] == pytest.approx(0.0, abs=0.05)  # north pole: the skin's top, z = 0


def test_tick_pose_on_the_axis_equals_tick_by_depth(short_scene):
    by_depth, by_pose = puncture.Simulator(short_scene), puncture.Simulator(short_scene)
    for i in range(300):
        a = by_depth.tick(i * 0.01, velocity_mm_per_s=10.0, time_s=i * 1e-3)
        b = by_pose.tick_pose([0.0, 0.0, -i * 0.01], [0.0, 0.0, -1.0], 10.0, time_s=i * 1e-3)
    assert b.force_N == pytest.approx(a.force_N, rel=1e-12) and a.force_N > 0.0


@pytest.fixture(scope="module")
def oblique_scene(short_scene):
    """The short default insertion with the needle at 30 deg to the surface normal."""
    return short_scene.updated({"name": "default_short_30deg", "insertion/angle_deg": 30.0})


def test_an_inclined_run_equals_the_programs_csv_and_resolves_its_force(oblique_scene, program, tmp_path):
    r = puncture.Simulator(oblique_scene).run()
    scene_path = tmp_path / "oblique.json"
    oblique_scene.save(scene_path)
    run_program(program, "run", scene_path, "-o", tmp_path / "out", "--no-frames", "-q")
    csv_columns = read_program_curve(tmp_path / "out" / "realtime_curve.csv")
    for name in ["depth_mm", "path_depth_mm", "force_N", "lateral_force_N"]:
        np.testing.assert_array_equal(np.array(csv_columns[name], dtype=float), r[name], err_msg=name)
    for c, axis in enumerate("xyz"):
        np.testing.assert_array_equal(np.array(csv_columns[f"force_{axis}_N"], dtype=float), r.force_vector_N[:, c])
        np.testing.assert_array_equal(np.array(csv_columns[f"torque_{axis}_N_m"], dtype=float),
                                      r.torque_about_entry_N_m[:, c])
    # The needle's axis d = (sin 30, 0, -cos 30): the force along -d is force_N, across it lateral_force_N.
    d = np.array([np.sin(np.radians(30.0)), 0.0, -np.cos(np.radians(30.0))])
    f = r.force_vector_N
    np.testing.assert_allclose(-f @ d, r.force_N, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(f - np.outer(f @ d, d), axis=1), r.lateral_force_N, atol=1e-12)
    np.testing.assert_allclose(r.path_depth_mm, r.depth_mm / np.cos(np.radians(30.0)), rtol=1e-12, atol=1e-12)
    # While the skin is pressed the tip's load acts along the surface normal: lateral / axial = tan 30.
    pressed = (r.layer_state[:, 0] == r.state_names.index("pressed")) & (r.surface_force_N > 0.1)
    assert pressed.sum() > 100
    np.testing.assert_allclose(r.lateral_force_N[pressed] / r.force_N[pressed], np.tan(np.radians(30.0)), rtol=1e-6)


def test_tick_by_depth_follows_the_scenes_inclined_line(oblique_scene):
    by_depth, by_pose = puncture.Simulator(oblique_scene), puncture.Simulator(oblique_scene)
    d = np.array([np.sin(np.radians(30.0)), 0.0, -np.cos(np.radians(30.0))])
    for i in range(300):
        depth = i * 0.01
        a = by_depth.tick(depth, velocity_mm_per_s=10.0, time_s=i * 1e-3)
        b = by_pose.tick_pose(d * depth / np.cos(np.radians(30.0)), d, 10.0, time_s=i * 1e-3)
    assert a.force_N > 0.0 and a.lateral_force_N > 0.0
    assert b.force_N == pytest.approx(a.force_N, rel=1e-12)
    assert a.path_depth_mm == pytest.approx(2.99 / np.cos(np.radians(30.0)))


def test_the_azimuth_turns_the_force_vector_about_the_sample_axis(oblique_scene):
    # The flat slab is rotationally symmetric: at azimuth 120 deg the run is the one at 0 deg turned by 120 deg.
    turned = puncture.Simulator(oblique_scene.updated({"insertion/azimuth_deg": 120.0})).run()
    r = puncture.Simulator(oblique_scene).run()
    b = np.radians(120.0)
    turn = np.array([[np.cos(b), -np.sin(b), 0.0], [np.sin(b), np.cos(b), 0.0], [0.0, 0.0, 1.0]])
    scale = 1e-12 * (1.0 + np.abs(r.force_vector_N).max())
    np.testing.assert_allclose(turned.force_vector_N, r.force_vector_N @ turn.T, atol=scale)
    np.testing.assert_allclose(turned.torque_about_entry_N_m, r.torque_about_entry_N_m @ turn.T, atol=scale)
    np.testing.assert_allclose(turned.force_N, r.force_N, atol=scale)
    assert np.abs(turned.force_vector_N[:, 1]).max() > 0.01  # the needle now tilts out of the x-z plane
    with pytest.raises(ValueError, match="azimuth_deg"):
        oblique_scene.updated({"insertion/azimuth_deg": 360.0})


def test_bad_ticks_raise(short_scene):
    sim = puncture.Simulator(short_scene)
    with pytest.raises(ValueError, match="finite"):
        sim.tick(float("nan"))
    with pytest.raises(ValueError, match="direction"):
        sim.tick_pose([0, 0, 0], [0, 0, 0], 1.0)
    with pytest.raises(KeyError, match="bone"):
        sim.force_mesh_nodes_mm("bone")


def test_run_needs_fresh_tissue_and_reset_gives_it(short_scene):
    sim = puncture.Simulator(short_scene)
    sim.tick(0.0)
    with pytest.raises(RuntimeError, match="reset"):
        sim.run()
    sim.reset()
    assert sim.ticks == 0 and len(sim.run()) > 0


def test_run_reports_progress_and_a_raising_callback_stops_it(short_scene):
    fractions = []
    puncture.Simulator(short_scene).run(progress=fractions.append)
    assert fractions[-1] == 1.0 and fractions == sorted(fractions) and len(fractions) >= 10

    class Stop(Exception):
        pass

    def stop_at_half(fraction):
        if fraction > 0.5:
            raise Stop()

    sim = puncture.Simulator(short_scene)
    with pytest.raises(Stop):
        sim.run(progress=stop_at_half)
    assert sim.ticks == 0  # back to fresh tissue
