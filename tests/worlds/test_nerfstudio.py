"""``davis-ag export nerfstudio``: transforms.json in nerfstudio's convention, checked by projecting
each fruit's recorded centre through the exported matrices into its exported mask."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from PIL import Image

from davis_ag import cli


def project(frame: dict, meta: dict, point: list[float]) -> tuple[float, float, float]:
    """A world point to (column, row, distance in front) through nerfstudio's convention, written
    from its documentation alone: camera-to-world with +x right, +y up, +z back, pixel centres at +0.5."""
    c2w = np.asarray(frame["transform_matrix"])
    camera = c2w[:3, :3].T @ (np.asarray(point) - c2w[:3, 3])
    ahead = -camera[2]
    return meta["cx"] + meta["fl_x"] * camera[0] / ahead, meta["cy"] - meta["fl_y"] * camera[1] / ahead, ahead


def test_each_visible_fruits_centre_projects_into_its_mask(
    world_root: Path, world_scene_dir: Path, tmp_path: Path
) -> None:
    out = tmp_path / "ns"
    assert cli.main(["export", "nerfstudio", str(world_root), str(out)]) == 0
    folder = out / world_scene_dir.relative_to(world_root)
    meta = json.loads((folder / "transforms.json").read_text())
    scene = json.loads((world_scene_dir / "scene.json").read_text())
    annotations = json.loads((world_scene_dir / "annotations.json").read_text())
    assert (meta["camera_model"], meta["w"], meta["h"]) == (
        "OPENCV",
        scene["camera"]["width"],
        scene["camera"]["height"],
    )
    assert len(meta["frames"]) == len(annotations)
    centres = {f["id"]: f["center"] for f in scene["fruits"]}
    landed = checked = 0
    for frame in meta["frames"]:
        image = (folder / frame["file_path"]).resolve()
        assert image.parent.parent == world_scene_dir.resolve()  # referenced in the dataset, not copied
        mask = np.asarray(Image.open(folder / frame["fruit_mask_path"]))
        depth = np.asarray(Image.open(folder / frame["depth_file_path"]))
        assert depth.dtype == np.uint16 and mask.shape == (meta["h"], meta["w"])
        for fruit, fraction in scene["visible_fraction"][image.name].items():
            u, v, ahead = project(frame, meta, centres[int(fruit)])
            assert ahead > 0, (image.name, fruit)
            # a leaf may hide the centre of a fruit seen in part, and the image's edge cut it off
            if fraction < 1.0 or not (1 <= u < meta["w"] - 1 and 1 <= v < meta["h"] - 1):
                continue
            checked += 1
            window = np.s_[int(v) - 1 : int(v) + 2, int(u) - 1 : int(u) + 2]  # the pixel and its neighbours
            on_fruit = mask[window] == int(fruit)
            landed += int(on_fruit.any())
            # the depth image agrees: the fruit's surface is nearer than its centre, by less than its size
            assert on_fruit.any() and 0 < ahead * 1000 - depth[window][on_fruit].min() < 60
    assert checked > 20 and landed == checked, f"{landed} of {checked} fully visible fruit centres in their masks"
    # A wrong convention (OpenCV's +y down, +z forward) puts the fruit behind the camera or elsewhere.
    flipped = dict(meta["frames"][0])
    flipped["transform_matrix"] = (np.asarray(flipped["transform_matrix"]) @ np.diag([1, -1, -1, 1])).tolist()
    fruit = next(iter(scene["visible_fraction"][Path(flipped["file_path"]).name]))
    assert project(flipped, meta, centres[int(fruit)])[2] < 0


def test_copied_files_make_a_folder_of_its_own(world_root: Path, world_scene_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "ns"
    assert cli.main(["export", "nerfstudio", str(world_scene_dir), str(out), "--copy"]) == 0
    folder = out / world_scene_dir.relative_to(world_root)
    meta = json.loads((folder / "transforms.json").read_text())
    frame = meta["frames"][0]
    for key in ("file_path", "depth_file_path", "fruit_mask_path", "class_path"):
        assert frame[key].startswith("images/") and (folder / frame[key]).is_file()
    original = world_scene_dir / "images" / Path(frame["file_path"]).name
    assert (folder / frame["file_path"]).read_bytes() == original.read_bytes()
