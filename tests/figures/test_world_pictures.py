"""The picture of an exported labelled mesh, drawn from its PLY alone."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from davis_ag.data.reader import open_dataset
from davis_ag.figures.label_pictures import ORGAN_COLOURS
from davis_ag.figures.world_pictures import draw_mesh, read_mesh
from davis_ag.render.scene_geometry import COLOUR, SceneGeometry
from davis_ag.scene.organs import FRUIT, LEAF, ORGAN_NAMES, SOIL
from davis_ag.worlds.mesh import ply_bytes
from davis_ag.worlds.triangles import NONE, WorldTriangles


def test_a_small_mesh_reads_back_and_draws_each_class(sp_root: Path, tmp_path: Path) -> None:
    scene = open_dataset(sp_root).scenes[0]
    positions = np.array(
        [
            [[-1, -1, 0], [1, -1, 0], [1, 1, 0]],  # soil
            [[-1, -1, 0], [1, 1, 0], [-1, 1, 0]],  # soil
            [[0, 0, 0.1], [0.3, 0, 0.3], [0, 0.3, 0.3]],  # a leaf
            [[0.1, 0.1, 0.2], [0.2, 0.1, 0.2], [0.15, 0.15, 0.3]],  # a fruit
        ],
        dtype=np.float32,
    )
    n = len(positions)
    geometry = SceneGeometry(
        positions,
        np.zeros((n, 3, 2), np.float32),
        np.tile(np.float32([0, 0, 1]), (n, 3, 1)),
        np.arange(n, dtype=np.uint32),
        np.ones((n, 4), np.float32),
        np.full(n, -1, np.int32),
        np.full(n, COLOUR, np.int32),
        np.array([False, False, True, True]),
        np.zeros(n, bool),
    )
    world = WorldTriangles(
        scene,
        geometry,
        np.array([SOIL, SOIL, LEAF, FRUIT], np.uint8),
        np.array([NONE, NONE, NONE, 0], np.int32),
        np.array([NONE, NONE, 0, 0], np.int32),
        np.array([[100, 80, 60], [100, 80, 60], [30, 160, 30], [200, 20, 20]], np.uint8),
        ORGAN_NAMES,
    )
    ply = tmp_path / "mesh.ply"
    ply.write_bytes(ply_bytes(world))
    mesh = read_mesh(ply)
    assert np.allclose(mesh["corners"], positions)
    assert list(mesh["organ"]) == [SOIL, SOIL, LEAF, FRUIT] and list(mesh["fruit_id"]) == [255, 255, 255, 0]
    assert list(mesh["plant"]) == [-1, -1, 0, 0] and list(mesh["names"]) == list(ORGAN_NAMES)
    picture = draw_mesh(ply, tmp_path / "mesh.png", margin=1.0)  # the soil triangles reach 1 m out
    pixels = np.asarray(Image.open(picture).convert("RGB")).reshape(-1, 3)
    for organ in (SOIL, LEAF, FRUIT):  # each class's colour is drawn (panel or legend)
        assert (np.abs(pixels.astype(int) - ORGAN_COLOURS[organ]).sum(axis=1) < 12).any(), ORGAN_NAMES[organ]
