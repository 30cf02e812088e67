"""puncture.Scene: files, dicts, fields by JSON path, the reader's validation."""
import json
import re
import math

import pytest

import puncture
from conftest import run_program


def test_dict_round_trip_reproduces_the_scene(default_scene):
    d = default_scene.to_dict()
    again = puncture.Scene.from_dict(d)
    assert again == default_scene
    assert again.to_dict() == d
    assert d["layers"][0]["name"] == "skin"


def test_save_then_load_reproduces_the_scene_and_leaves_no_staged_file(default_scene, tmp_path):
    path = tmp_path / "saved.json"
    default_scene.save(path)
    assert puncture.Scene.load(path) == default_scene
    assert [p.name for p in tmp_path.iterdir()] == ["saved.json"]
    assert json.loads(path.read_text()) == default_scene.to_dict()


def test_get_and_set_a_field_by_json_path(default_scene):
    scene = default_scene.copy()
    assert scene.get("layers/0/thickness_mm") == pytest.approx(0.8)
    scene.set("layers/0/thickness_mm", 1.2)
    assert scene.get("/layers/0/thickness_mm") == pytest.approx(1.2)
    assert default_scene.get("layers/0/thickness_mm") == pytest.approx(0.8)  # copy() is a copy
    assert scene.layer_names == ["skin", "fat", "muscle"]
    scene["layers/2/thickness_mm"] = 30.0  # the same as set() and get()
    assert scene["layers/2/thickness_mm"] == 30.0


def test_updated_sets_several_fields_at_once(default_scene):
    scene = default_scene.updated({"insertion/target_depth_mm": 12.0, "insertion/dwell_s": 0.5})
    assert (scene.get("insertion/target_depth_mm"), scene.get("insertion/dwell_s")) == (12.0, 0.5)


def test_bad_value_raises_scene_error_naming_the_path_and_keeps_the_scene(default_scene):
    scene = default_scene.copy()
    with pytest.raises(puncture.SceneError) as raised:
        scene.set("layers/1/thickness_mm", -2.0)
    assert raised.value.json_path == "/layers/1/thickness_mm"
    assert "/layers/1/thickness_mm: must be > 0 (got -2)" in str(raised.value)
    assert isinstance(raised.value, ValueError) and isinstance(raised.value, puncture.InputError)
    assert scene == default_scene


@pytest.mark.parametrize("path, value, words", [
    ("layers/0/no_such_key", 1.0, "/layers/0/no_such_key"),
    ("layers/0/thickness_mm", math.nan, "/layers/0/thickness_mm: must be a finite number"),
    ("layers/0/thickness_mm", "thick", "/layers/0/thickness_mm"),
    ("layers/9/thickness_mm", 1.0, "/layers/9/thickness_mm"),
])
def test_every_bad_field_names_its_path(default_scene, path, value, words):
    with pytest.raises(puncture.SceneError, match=re.escape(words)):
        default_scene.copy().set(path, value)


def test_missing_field_is_a_key_error(default_scene):
    with pytest.raises(KeyError, match="/layers/0/nothing"):
        default_scene.get("layers/0/nothing")


def test_a_bad_file_gives_the_command_lines_message(default_scene, program, tmp_path):
    d = default_scene.to_dict()
    d["layers"][2]["force_mesh"]["w"] = 0
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(d))
    with pytest.raises(puncture.SceneError) as raised:
        puncture.Scene.load(path)
    done = run_program(program, "run", path, "-o", tmp_path / "out", "--no-frames", "-q", check=False)
    assert done.returncode == 2
    assert done.stderr.strip() == "error: " + str(raised.value)
    assert raised.value.file == str(path) and raised.value.json_path == "/layers/2/force_mesh/w"
    assert not (tmp_path / "out").exists()


def test_a_missing_file_is_a_scene_error(tmp_path):
    with pytest.raises(puncture.SceneError, match="cannot open scene file"):
        puncture.Scene.load(tmp_path / "absent.json")


def test_from_dict_names_its_source_in_messages(default_scene):
    d = default_scene.to_dict()
    d["insertion"]["speed_mm_per_s"] = -1.0
    with pytest.raises(puncture.SceneError, match=r"^study-3: /insertion/speed_mm_per_s: "):
        puncture.Scene.from_dict(d, source="study-3")


def test_save_where_nothing_can_be_written_is_an_output_error(default_scene, tmp_path):
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    with pytest.raises(puncture.OutputError, match="a_file"):
        default_scene.save(blocker / "scene.json")
    assert isinstance(puncture.OutputError("x"), OSError)
