"""The picture of an exported labelled mesh, drawn from its PLY alone."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from davis_ag.figures.label_pictures import ORGAN_COLOURS
from davis_ag.figures.world_pictures import draw_mesh, read_mesh
from davis_ag.scene.organs import FRUIT, LEAF, ORGAN_NAMES, SOIL
from davis_ag.worlds.mesh import ply_bytes
from davis_ag.worlds.triangles import WorldTriangles


def test_a_small_mesh_reads_back_and_draws_each_class(tiny_world: WorldTriangles, tmp_path: Path) -> None:
    positions = tiny_world.geometry.positions
    ply = tmp_path / "mesh.ply"
    ply.write_bytes(ply_bytes(tiny_world))
    mesh = read_mesh(ply)
    assert np.allclose(mesh["corners"], positions)
    assert list(mesh["organ"]) == [SOIL, SOIL, LEAF, FRUIT] and list(mesh["fruit_id"]) == [255, 255, 255, 0]
    assert list(mesh["plant"]) == [-1, -1, 0, 0] and list(mesh["names"]) == list(ORGAN_NAMES)
    picture = draw_mesh(ply, tmp_path / "mesh.png", margin=1.0)  # the soil triangles reach 1 m out
    pixels = np.asarray(Image.open(picture).convert("RGB")).reshape(-1, 3)
    for organ in (SOIL, LEAF, FRUIT):  # each class's colour is drawn (panel or legend)
        assert (np.abs(pixels.astype(int) - ORGAN_COLOURS[organ]).sum(axis=1) < 12).any(), ORGAN_NAMES[organ]
