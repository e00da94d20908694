"""The exports' labelled triangles: each triangle's organ class and fruit id are what the dataset's
own class and instance images show where that triangle is the visible surface."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from davis_ag.data.reader import open_dataset
from davis_ag.formats.layout import LIVE_GEOMETRY
from davis_ag.generate.recorded_settings import read_settings
from davis_ag.live import reopen
from davis_ag.scene.organs import FRUIT, SOIL
from davis_ag.worlds.cameras import camera_to_world
from davis_ag.worlds.triangles import NONE, parts, world_triangles


def test_labels_agree_with_the_class_and_instance_images(world_scene_dir: Path) -> None:
    (scene,) = open_dataset(world_scene_dir).scenes
    world = world_triangles(scene)
    camera = scene.metadata.camera
    centroids = world.geometry.positions.mean(axis=1).astype(np.float64)
    seen = agree_class = agree_fruit = fruit_seen = 0
    for view in list(scene)[::9]:
        c2w = camera_to_world(view.pose)
        local = (centroids - c2w[:3, 3]) @ c2w[:3, :3]  # OpenGL camera frame: +x right, +y up, +z back
        ahead = -local[:, 2]
        front = ahead > 0.05
        u = np.full(len(ahead), -1.0)
        v = np.full(len(ahead), -1.0)
        u[front] = camera.cx + camera.fx * local[front, 0] / ahead[front]
        v[front] = camera.cy - camera.fy * local[front, 1] / ahead[front]
        inside = front & (u >= 0) & (u < camera.width) & (v >= 0) & (v < camera.height)
        rows, cols = v[inside].astype(int), u[inside].astype(int)
        depth = np.asarray(Image.open(view.depth_path)).astype(np.float64)[rows, cols]
        surface = np.abs(depth - ahead[inside] * 1000) < 1.5  # this triangle is what the pixel shows
        faces = np.flatnonzero(inside)[surface]
        classes = view.classes()[rows[surface], cols[surface]]
        mask = view.mask()[rows[surface], cols[surface]]
        seen += len(faces)
        agree_class += int((classes == world.organ[faces]).sum())
        labelled = (world.fruit[faces] != NONE) & (mask != 255)  # boxed fruit only: the masks' rule
        fruit_seen += int(labelled.sum())
        agree_fruit += int((mask[labelled] == world.fruit[faces][labelled]).sum())
    assert seen > 1000 and fruit_seen > 20
    assert agree_class / seen > 0.97, f"{agree_class} of {seen}"
    assert agree_fruit / fruit_seen > 0.97, f"{agree_fruit} of {fruit_seen}"
    assert (world.organ[world.fruit != NONE] == FRUIT).all()
    named = parts(world)
    assert named[0].group == "environment" and named[0].organ == SOIL
    assert sum(len(p.faces) for p in named) == world.count


def test_a_cache_without_labels_is_regrown_once(
    world_scene_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    copy = tmp_path / world_scene_dir.parent.name / world_scene_dir.name
    shutil.copytree(world_scene_dir, copy)
    settings = read_settings(copy)
    assets = reopen.load_cache(copy / LIVE_GEOMETRY, reopen.cache_key(settings))
    assert assets is not None and assets.organ_of_uuid is not None
    assets.organ_of_uuid = assets.plant_of_uuid = None  # as a cache written before they were kept
    reopen.save_cache(copy / LIVE_GEOMETRY, reopen.cache_key(settings), assets)
    assert reopen.reopen_assets(settings).from_cache  # drawing needs no labels: the cache serves
    relabelled = reopen.reopen_assets(settings, labelled=True)
    assert not relabelled.from_cache and relabelled.organ_of_uuid is not None
    monkeypatch.setattr(reopen, "regrow", lambda settings: pytest.fail("regrown again"))
    again = reopen.reopen_assets(settings, labelled=True)
    assert again.from_cache and np.array_equal(again.plant_of_uuid, relabelled.plant_of_uuid)
