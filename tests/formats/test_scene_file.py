"""scene.json's model: what the generator writes reads back unchanged, older files still read, and a
damaged one is one line naming the field."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from davis_ag.errors import UserError
from davis_ag.formats.scene_file import SCENE_FORMAT, SceneFile, read_scene_file

#: A scene.json as the generator wrote it before plant_generator, appearance, classes and
#: min_fruit_pixels existed (keys of the first davis-ag-scene/1 files).
OLDER = {
    "format": SCENE_FORMAT,
    "generator": {"name": "davis-ag", "version": "0.1.0+abc", "pyhelios3d": "1.3.40", "python": "3.11.9"},
    "seed": 1234,
    "dataset_seed": 0,
    "scenario": "sp",
    "crop": "strawberry",
    "scene": "Single-Strawberry/007",
    "camera": {
        "model": "pinhole",
        "width": 1280,
        "height": 720,
        "fx": 869.1,
        "fy": 869.1,
        "cx": 640.0,
        "cy": 360.0,
        "vfov_deg": 45,
        "hfov_deg": 72.6,
        "distortion": [0.0, 0.0, 0.0, 0.0, 0.0],
    },
    "renderer": {"name": "helios", "look": "helios", "antialiasing": "4x multisampled colour"},
    "grid": {
        "extent_m": [1, 1.5],
        "step_m": 0.1,
        "altitudes_m": [0.25, 0.4],
        "headings": 1,
        "exclusion_radius_m": 0.2,
        "aim_height_m": 0.12,
        "views": 300,
    },
    "plants": [
        {
            "index": 0,
            "seed": 9,
            "position": [0.0, 0.0, 0.0],
            "phenotype_measured": {"plant_height": 0.2},
            "fruit_count": 2,
            "builds": 1,
        }
    ],
    "fruits": [{"id": 0, "plant": 0, "center": [0.01, 0.02, 0.1], "size": [0.03, 0.03, 0.04]}],
    "views": {"0001.jpeg": {"grid": [0, 0, 0, 0], "nominal": [0.0, -0.5, 0.25, 90, -20]}},
    "visible_fraction": {"0001.jpeg": {"0": 0.75, "1": 1}},
    "a_key_from_a_later_version": {"kept": True},
}


def test_an_older_scene_json_reads_and_dumps_back_as_written(tmp_path: Path) -> None:
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(OLDER))
    scene = read_scene_file(path)
    assert scene.ours and scene.index == 7 and scene.image_size() == (1280, 720)
    assert scene.plant_generator is None and scene.min_fruit_pixels is None and scene.classes is None
    assert scene.fruits[0].size == [0.03, 0.03, 0.04] and scene.plants[0].fruit_count == 2
    assert scene.visible_in("0001.jpeg") == {"0": 0.75, "1": 1} and scene.visible_in("0002.jpeg") == {}
    # Whole numbers stay whole and unknown keys stay: the dump is the file (the live cache keys on it).
    assert json.dumps(scene.as_written()) == json.dumps(OLDER)


def test_the_original_download_and_test_layouts_record_less_and_still_read() -> None:
    scene = SceneFile.model_validate({"seed": 3, "camera": {"width": 64, "height": 48}})
    assert not scene.ours and scene.plants == [] and scene.fruits == [] and scene.visible_fraction == {}
    assert scene.index is None and scene.image_size() == (64, 48)


@pytest.mark.parametrize(
    ("change", "named"),
    [
        ({"seed": "twelve"}, "seed"),
        ({"camera": {"width": 1280.5}}, "camera.width"),
        ({"fruits": [{"id": 0, "center": "middle"}]}, "fruits.0.center"),
        ({"visible_fraction": {"0001.jpeg": [0.5]}}, "visible_fraction.0001.jpeg"),
    ],
)
def test_a_damaged_field_is_one_line_naming_it(tmp_path: Path, change: dict, named: str) -> None:
    path = tmp_path / "scene.json"
    path.write_text(json.dumps({**OLDER, **change}))
    with pytest.raises(UserError) as raised:
        read_scene_file(path)
    message = str(raised.value)
    assert message.startswith(f"{path}: {named}:") and "\n" not in message and "regenerate" in message


@pytest.mark.parametrize("text", ["[1, 2]", "{not json", ""])
def test_a_file_that_is_no_json_object_is_one_line(tmp_path: Path, text: str) -> None:
    path = tmp_path / "scene.json"
    path.write_text(text)
    with pytest.raises(UserError, match=r"^.*scene\.json: .*regenerate the scene$"):
        read_scene_file(path)
