"""``davis-ag export mesh``: PLY read back with plyfile and GLB with trimesh, labels per face."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import trimesh
from plyfile import PlyData

from davis_ag import cli
from davis_ag.scene.organs import FRUIT, ORGAN_NAMES, SOIL


def test_ply_faces_carry_organ_fruit_and_plant(world_root: Path, world_scene_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "ply"
    assert cli.main(["export", "mesh", str(world_root), str(out)]) == 0
    ply = PlyData.read(str(out / f"{world_scene_dir.relative_to(world_root)}.ply"))
    scene = json.loads((world_scene_dir / "scene.json").read_text())
    assert [c.split() for c in ply.comments if c.startswith("class ")] == [
        ["class", str(v), name] for v, name in enumerate(ORGAN_NAMES)
    ]
    faces, vertex = ply["face"].data, ply["vertex"].data
    corners = np.stack([vertex["x"], vertex["y"], vertex["z"]], axis=1)[np.stack(faces["vertex_indices"])]
    assert faces["fruit_id"].dtype == np.uint8  # the masks' type: at most 255 fruit
    fruit = faces["fruit_id"] != 255
    assert (faces["organ"][fruit] == FRUIT).all()
    assert sorted(np.unique(faces["fruit_id"][fruit])) == [f["id"] for f in scene["fruits"]]
    for record in scene["fruits"]:
        mine = corners[faces["fruit_id"] == record["id"]].reshape(-1, 3)
        assert np.allclose((mine.min(axis=0) + mine.max(axis=0)) / 2, record["center"], atol=1e-5)
        assert (faces["plant"][faces["fruit_id"] == record["id"]] == record["plant"]).all()
    soil = faces["organ"] == SOIL
    assert soil.any() and (faces["plant"][soil] == -1).all() and np.abs(corners[soil][..., 2]).max() < 1e-3
    assert set(np.unique(faces["plant"][~soil])) == {p["index"] for p in scene["plants"]}


def test_glb_has_a_node_per_plant_organ_and_fruit(world_root: Path, world_scene_dir: Path, tmp_path: Path) -> None:
    out = tmp_path / "glb"
    assert cli.main(["export", "mesh", str(world_scene_dir), str(out), "--format", "glb"]) == 0
    loaded = trimesh.load(out / f"{world_scene_dir.relative_to(world_root)}.glb", force="scene")
    scene = json.loads((world_scene_dir / "scene.json").read_text())
    assert loaded.metadata["davis_ag"]["classes"] == list(ORGAN_NAMES)
    nodes = {name: loaded.graph[name] for name in loaded.graph.nodes_geometry}
    for record in scene["fruits"]:
        name = f"plant_{record['plant']:03d}/fruit_{record['id']}"
        matrix, geometry = nodes[name]
        mesh = loaded.geometry[geometry]
        assert mesh.metadata["fruit_id"] == record["id"] and mesh.metadata["organ"] == "fruit"
        # glTF is Y up: the node's matrix takes our Z-up metres there (x, y, z) -> (x, z, -y).
        x, y, z = record["center"]
        centre = trimesh.transform_points([mesh.bounds.mean(axis=0)], matrix)[0]
        assert np.allclose(centre, [x, z, -y], atol=1e-5)
    assert "environment/soil" in nodes and {f"plant_{p['index']:03d}/leaf" for p in scene["plants"]} <= set(nodes)
