"""Reopening a generated scene live: regrown bit for bit, cached, and drawn from any pose."""

from __future__ import annotations

import json
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from davis_ag.data.reader import open_dataset
from davis_ag.data.validate import validate_dataset
from davis_ag.errors import UserError
from davis_ag.formats.layout import LIVE_GEOMETRY
from davis_ag.generate.one_scene import SceneRequest, draw_scene, grow_scene
from davis_ag.generate.recorded_settings import read_settings
from davis_ag.live.reopen import regrow
from davis_ag.live.scene import LiveScene, merge_ground, open_live_scene


def test_a_grid_pose_drawn_live_is_the_stored_view(live_root: Path, live_scene: LiveScene) -> None:
    """Ids and boxes exactly, visible fractions as scene.json has them, colour within JPEG's error."""
    (scene,) = open_dataset(live_root).scenes
    stored = json.loads((scene.path / "scene.json").read_text())
    checked = 0
    for view in scene:
        live = live_scene.render(live_scene.grid_view(view.name))
        assert live.boxes == [
            list(b) for b in json.loads((scene.path / "annotations.json").read_text())[view.name]["bounding_boxes"]
        ]
        assert np.array_equal(live.segmentation, view.mask())
        assert live.visible_fraction == {int(k): v for k, v in stored["visible_fraction"][view.name].items()}
        jpeg = np.asarray(Image.open(scene.path / "images" / view.name)).astype(np.int64)
        assert np.abs(jpeg - live.colour).mean() < 4.0  # JPEG quality, not the drawing
        assert np.abs(live.depth - view.depth()).max() <= 0.0006  # stored as whole millimetres
        checked += len(live.boxes)
    assert checked > 0


def test_reopening_uses_the_cache_and_a_tampered_cache_is_rebuilt(
    live_scene_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from davis_ag.live import reopen

    # Read from the cache, never regrown (a regrow takes half a minute or more).
    monkeypatch.setattr(reopen, "regrow", lambda settings: pytest.fail("regrown, not read from the cache"))
    with open_live_scene(live_scene_dir) as scene:
        assert scene.assets.from_cache
    monkeypatch.undo()  # the rest regrows on purpose
    # The cache is keyed by scene.json: a scene whose seed changed ignores it (and cannot regrow).
    copy = tmp_path / "Single-Strawberry" / "000"
    shutil.copytree(live_scene_dir, copy)
    meta = json.loads((copy / "scene.json").read_text())
    meta["seed"] += 1
    (copy / "scene.json").write_text(json.dumps(meta))
    with pytest.raises(UserError, match="seed"):
        open_live_scene(copy)
    assert (copy / LIVE_GEOMETRY).read_bytes() == (live_scene_dir / LIVE_GEOMETRY).read_bytes()  # left alone


def test_a_scene_that_regrows_differently_is_refused(
    live_scene_dir: Path, tmp_path: Path, grown: tuple, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The regrown fruit registry is checked against scene.json's. The growth is the generator's
    own (the fixture's plants, reused to save half a minute); the record is what changes."""
    import davis_ag.generate.one_scene as one_scene

    copy = tmp_path / "Single-Strawberry" / "000"
    shutil.copytree(live_scene_dir, copy)
    monkeypatch.setattr(one_scene, "grow_scene", lambda request: grown)
    assert regrow(read_settings(copy)).fruit_uuids  # as stored: accepted
    meta = json.loads((copy / "scene.json").read_text())
    meta["fruits"][0]["center"][0] += 1e-6
    (copy / "scene.json").write_text(json.dumps(meta))
    with pytest.raises(UserError, match="other plants"):
        regrow(read_settings(copy))


def test_only_our_scenes_reopen(sp_root: Path, tmp_path: Path) -> None:
    with pytest.raises(UserError, match="davis-ag generate"):
        open_live_scene(sp_root / "Single-Strawberry" / "000")  # written by the tests' layout factory
    with pytest.raises(UserError, match="missing"):
        open_live_scene(tmp_path)


def test_any_pose_at_any_size(live_scene: LiveScene) -> None:
    aimed = live_scene.aimed_pose(0.9, -0.6, 0.33)
    view = live_scene.render(aimed, width=128, height=128)
    assert view.colour.shape == (128, 128, 3) and view.depth.shape == (128, 128)
    assert view.boxes, "the plant's fruit are in front of an aimed camera"
    for x0, y0, w, h, fruit, _ in view.boxes:
        mask = view.segmentation == fruit
        rows, cols = np.nonzero(mask)
        assert (x0, y0, w, h) == (cols.min(), rows.min(), np.ptp(cols) + 1, np.ptp(rows) + 1)
        assert view.oer[fruit] == pytest.approx(mask.sum() / (w * h))
        assert 0 < view.visible_fraction[fruit] <= 1
    # The aimed pose looks at the plant: its centre projects to the middle of the image.
    assert abs(aimed.yaw - np.degrees(np.arctan2(0.6, -0.9))) < 1e-9
    # A free pose turned away from the plant sees no fruit, only soil and sky.
    away = live_scene.render(live_scene.pose(0.9, -0.6, 0.33, yaw=aimed.yaw + 180, pitch=0), 128, 128)
    assert away.boxes == [] and (away.segmentation == 255).all()


def test_a_view_without_depth_is_the_same_view(live_scene: LiveScene) -> None:
    """As TVMContinuous-v0 draws (224x224, no antialiasing, merged soil, no depth): the same colour,
    labels and OER as with the depth, for poses aimed at the plant and poses that put fruit at the
    frame's edge or out of it."""
    aimed = live_scene.aimed_pose(0.9, -0.6, 0.33)
    poses = [
        aimed,
        live_scene.aimed_pose(-0.5, 0.4, 0.5),
        live_scene.aimed_pose(0.3, 0.35, 0.2),
        *(
            live_scene.pose(0.9, -0.6, 0.33, yaw=aimed.yaw + turn, pitch=aimed.pitch + tilt)
            for turn, tilt in ((14, 0), (-16, 4), (0, 15), (25, -10), (180, 0))
        ),
    ]
    boxes_at_the_edge = 0
    for pose in poses:
        with_depth = live_scene.render(pose, 224, 224, antialiasing="none", fractions=False, fast_ground=True)
        without = live_scene.render(pose, 224, 224, antialiasing="none", fractions=False, fast_ground=True, depth=False)
        assert without.depth is None and with_depth.depth.shape == (224, 224)
        assert np.array_equal(without.colour, with_depth.colour)
        assert np.array_equal(without.segmentation, with_depth.segmentation)
        assert without.boxes == with_depth.boxes and without.oer == with_depth.oer
        boxes_at_the_edge += sum(
            x0 == 0 or y0 == 0 or x0 + w == 224 or y0 + h == 224 for x0, y0, w, h, _, _ in without.boxes
        )
    assert boxes_at_the_edge > 0


def test_merged_soil_draws_the_same_image(live_scene: LiveScene) -> None:
    geometry = live_scene.assets.geometry
    assert merge_ground(geometry).triangle_count < geometry.triangle_count - 10_000
    view = live_scene.grid_view("0003.jpeg")
    full = live_scene.render(view, 128, 128, antialiasing="none", fractions=False)
    fast = live_scene.render(view, 128, 128, antialiasing="none", fractions=False, fast_ground=True)
    assert fast.boxes == full.boxes and np.array_equal(fast.segmentation, full.segmentation)
    assert np.abs(fast.colour.astype(np.int64) - full.colour).max() <= 2


def test_the_cache_is_no_stranger_to_the_dataset(live_root: Path) -> None:
    assert (live_root / "Single-Strawberry" / "000" / LIVE_GEOMETRY).is_file()
    assert validate_dataset(live_root).ok


def test_a_scene_whose_cache_cannot_be_written_reopens_uncached(
    live_scene_dir: Path,
    tmp_path: Path,
    grown: tuple,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A folder in the cache file's place: the scene still opens (regrown), says so in one line
    and leaves the folder alone."""
    import davis_ag.generate.one_scene as one_scene

    copy = tmp_path / "Single-Strawberry" / "000"
    shutil.copytree(live_scene_dir, copy)
    (copy / LIVE_GEOMETRY).unlink()
    (copy / LIVE_GEOMETRY).mkdir()
    (copy / LIVE_GEOMETRY / "keep").write_text("mine")
    monkeypatch.setattr(one_scene, "grow_scene", lambda request: grown)
    with open_live_scene(copy) as scene:
        assert not scene.assets.from_cache and scene.assets.grid_views
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot cache" in err[0]
    assert (copy / LIVE_GEOMETRY / "keep").read_text() == "mine"


def test_a_random_appearance_scene_reopens_in_its_own_light(
    tmp_path: Path, live_request: SceneRequest, live_scene: LiveScene
) -> None:
    """Soil, sun, sky, exposure and sensor noise are drawn from the scene's seed: regrown or read
    from the cache, a grid pose draws as stored, and a free pose draws the same noise every time."""
    request = replace(live_request, appearance="random")
    scene_dir, _ = draw_scene(request, *grow_scene(request), tmp_path)
    stored = np.asarray(Image.open(scene_dir / "images" / "0003.jpeg")).astype(np.int64)
    free = live_scene.aimed_pose(0.9, -0.6, 0.33)
    drawn = []
    for from_cache in (False, True):
        with open_live_scene(scene_dir) as scene:
            assert scene.assets.from_cache == from_cache and scene.settings.appearance == "random"
            grid = scene.render(scene.grid_view("0003.jpeg"), fractions=False)
            assert np.abs(stored - grid.colour).mean() < 4.0  # JPEG quality, not the drawing
            drawn.append((grid.colour, scene.render(free, 64, 64, fractions=False).colour))
    assert all(np.array_equal(a, b) for a, b in zip(*drawn))
    paper = live_scene.render(live_scene.grid_view("0003.jpeg"), fractions=False).colour
    assert np.abs(paper.astype(np.int64) - drawn[0][0]).mean() > 8.0  # another light, another soil
