"""The pictures of a USD stage and a nerfstudio set, each drawn from the exported files alone."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from davis_ag.figures.export_pictures import draw_nerfstudio, draw_usd_stage, project, read_stage
from davis_ag.worlds.cameras import camera_to_world
from davis_ag.worlds.triangles import WorldTriangles

RED = np.array([0xD6, 0x27, 0x28])  # a drawn camera
YELLOW = np.array([255, 255, 0])  # a projected fruit centre seen in the view


def has_colour(picture: Path, colour: np.ndarray, tolerance: int = 40) -> bool:
    pixels = np.asarray(Image.open(picture).convert("RGB")).reshape(-1, 3).astype(int)
    return bool((np.abs(pixels - colour).sum(axis=1) < tolerance).any())


def test_a_stage_reads_back_its_triangles_and_cameras_and_draws_them(
    tiny_world: WorldTriangles, tmp_path: Path
) -> None:
    pytest.importorskip("pxr")
    from davis_ag.worlds.usd import write_stage

    counts = write_stage(tiny_world, tmp_path / "usd")
    stage = read_stage(tmp_path / "usd" / "scene.usd")
    # The same triangles (grouped by plant and organ, so in another order), in world metres.
    assert sorted(map(tuple, stage["corners"].reshape(-1, 9).round(5))) == sorted(
        map(tuple, tiny_world.geometry.positions.reshape(-1, 9).astype(float).round(5))
    )
    assert len(stage["cameras"]) == counts["cameras"] > 0
    posed = [view.pose for view in tiny_world.scene if view.pose is not None]
    assert np.allclose(stage["cameras"][0], camera_to_world(posed[0]), atol=1e-5)
    picture = draw_usd_stage(tmp_path / "usd" / "scene.usd", tmp_path / "usd.png", margin=0.2)
    assert has_colour(picture, RED)


def test_a_frame_s_fruit_centre_projects_through_nerfstudio_s_convention_and_is_drawn(tmp_path: Path) -> None:
    # A camera 2 m south of the origin and 1 m up, looking north: in nerfstudio's OpenGL convention
    # its -z is world +y and its +y world +z.
    c2w = np.eye(4)
    c2w[:3, :3] = np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]]).T
    c2w[:3, 3] = [0.0, -2.0, 1.0]
    meta = {"fl_x": 100.0, "fl_y": 100.0, "cx": 80.0, "cy": 45.0, "w": 160, "h": 90}
    frame = {"file_path": "0001.png", "transform_matrix": c2w.tolist()}
    # 0.2 m right of and 0.1 m above the optical axis, 2 m ahead: 10 px right, 5 px up of the centre.
    assert project(frame, meta, np.array([0.2, 0.0, 1.1])) == pytest.approx((90.0, 40.0, 2.0))
    assert project(frame, meta, np.array([0.0, -3.0, 1.0]))[2] < 0  # behind the camera
    Image.fromarray(np.full((90, 160, 3), 90, np.uint8)).save(tmp_path / "0001.png")
    (tmp_path / "transforms.json").write_text(json.dumps({**meta, "frames": [frame]}))
    scene = {"fruits": [{"id": 3, "center": [0.2, 0.0, 1.1]}], "visible_fraction": {"0001.png": {"3": 1.0}}}
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    picture = draw_nerfstudio(tmp_path / "transforms.json", tmp_path / "scene.json", tmp_path / "ns.png")
    assert has_colour(picture, YELLOW) and has_colour(picture, RED)
