"""Our OpenGL renderer against Helios's Visualizer on a real strawberry scene, in the helios look.

The fidelity thresholds are the project's (issue 9): ids differ on at most 0.01 % of pixels,
every boxed fruit's mask has IoU >= 0.999 between the two, boxes agree within 1 pixel, and the
mean absolute colour difference is at most 2/255. Depth must agree with Helios's and with the
pinhole model of :class:`davis_ag.scene.camera.Camera`.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest

from davis_ag.labels.fruit_labels import fruit_lookup, label_view
from davis_ag.render.backends import open_renderer, resolve_look
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import CROPS, SCENARIOS, plant_centres
from davis_ag.scene.view_grid import build_view_grid
from helios_reference import helios_reference

#: The size datasets are drawn at (the paper's). At 640x360 the far soil near the horizon, its
#: texture minified several times over, is sampled differently by the two: a median of 2.1/255 in
#: mean colour over every ninth view of this scene (47), 38 of them above 2/255; at 1280x720 a
#: median of 1.0/255 and at most 1.2 (measured 2026-11-23).
CAMERA = Camera(1280, 720)
#: Views of the scene's grid: low, middle and high altitude, different sides of the plant.
VIEW_INDICES = (40, 150, 260)
#: The crop's box threshold (section III-C): the fruit a dataset boxes.
MIN_FRUIT_PIXELS = CROPS["strawberry"].min_fruit_pixels


@pytest.fixture(scope="module")
def frames() -> Iterator[dict]:
    """Both renderers' frames of the same views of one grown strawberry scene."""
    from davis_ag.scene.build import build_scene
    from davis_ag.scene.plants import require_native_helios

    require_native_helios()
    scenario, crop = SCENARIOS["sp"], CROPS["strawberry"]
    rng = np.random.default_rng(7)
    model = build_scene(scenario, crop, rng)
    grid = build_view_grid(scenario, crop, plant_centres(scenario, crop), model.aim_height, rng)
    views = [grid.viewpoints[i] for i in VIEW_INDICES]
    out: dict = {"views": views, "model": model}
    for name in ("helios", "opengl"):
        with open_renderer(name, model.context, CAMERA, model.lighting, "helios") as renderer:
            out[name] = [renderer.render(view) for view in views]
    yield out


@helios_reference
def test_ids_match_helios(frames: dict) -> None:
    differ = sum(int((ours[1] != ref[1]).sum()) for ours, ref in zip(frames["opengl"], frames["helios"]))
    pixels = len(frames["views"]) * CAMERA.width * CAMERA.height
    assert differ / pixels <= 1e-4, f"{differ} of {pixels} pixels see another primitive"
    for ours, _ in zip(frames["opengl"], frames["helios"]):
        assert ours[1].dtype == np.uint32 and ours[1].shape == (CAMERA.height, CAMERA.width)
        assert (ours[1][0] == 0).all()  # the top row is sky


@helios_reference
def test_fruit_masks_and_boxes_match_helios(frames: dict) -> None:
    model = frames["model"]
    lookup = fruit_lookup({f.id: f.uuids for f in model.fruits}, model.uuid_count)
    compared = 0
    for ours, ref in zip(frames["opengl"], frames["helios"]):
        mine, theirs = label_view(ours[1], lookup, MIN_FRUIT_PIXELS), label_view(ref[1], lookup, MIN_FRUIT_PIXELS)
        boxes = {b[4]: b for b in theirs.boxes}
        assert {b[4] for b in mine.boxes} == set(boxes)
        for box in mine.boxes:
            other = boxes[box[4]]
            assert np.abs(np.subtract(box[:4], other[:4])).max() <= 1, (box, other)
            a, b = mine.segmentation == box[4], theirs.segmentation == box[4]
            assert (a & b).sum() / (a | b).sum() >= 0.999, f"fruit {box[4]}"
            compared += 1
    assert compared >= 3  # the views do see fruit


def test_colour_matches_helios(frames: dict) -> None:
    for ours, ref in zip(frames["opengl"], frames["helios"]):
        assert ours[0].dtype == np.uint8 and ours[0].shape == (CAMERA.height, CAMERA.width, 3)
        difference = np.abs(ours[0].astype(np.int16) - ref[0]).mean()
        assert difference <= 2.0, f"mean colour difference {difference:.2f}/255"


def test_depth_matches_helios_and_the_pinhole_model(frames: dict) -> None:
    model = frames["model"]
    for view, ours, ref in zip(frames["views"], frames["opengl"], frames["helios"]):
        ids, depth = ours[1], ours[2]
        assert depth.dtype == np.float32
        assert ((depth > 0) == (ids > 0)).all()  # 0 exactly where nothing is hit
        same = (ids == ref[1]) & (ids > 0)
        assert np.abs(depth[same] - ref[2][same]).max() <= 1e-3 + 1e-3 * depth[same].max()
        # A fruit's pixels lie between its nearest and farthest points along the optical axis.
        for fruit in model.fruits:
            pixels = np.isin(ids, fruit.uuids + 1)
            if pixels.sum() < MIN_FRUIT_PIXELS:
                continue
            _, along = CAMERA.project(view, np.concatenate([p.reshape(-1, 3) for p in fruit.polygons]))
            assert along.min() - 1e-3 <= depth[pixels].min() and depth[pixels].max() <= along.max() + 1e-3


@helios_reference
def test_default_look_keeps_the_geometry(frames: dict) -> None:
    """The default look changes textures, not where things are: fruit are where Helios sees them."""
    model = frames["model"]
    view = frames["views"][1]
    with open_renderer("opengl", model.context, CAMERA, model.lighting) as renderer:
        colour, ids, _ = renderer.render(view)
    ref = frames["helios"][1][1]
    fruit = np.concatenate([f.uuids for f in model.fruits]) + 1
    a, b = np.isin(ids, fruit), np.isin(ref, fruit)
    assert (a & b).sum() / (a | b).sum() > 0.98
    assert np.abs(colour.astype(np.int16) - frames["helios"][1][0]).mean() > 2  # a different look


@pytest.mark.parametrize("antialiasing", ["msaa", "none"])
def test_every_antialiasing_gives_the_same_ids_and_depth(frames: dict, antialiasing: str) -> None:
    """The default (FXAA along silhouettes), 4x multisampling and none: ids and depth are the same,
    and every colour is within the fidelity limit of Helios's frames."""
    model = frames["model"]
    view = frames["views"][0]
    with open_renderer("opengl", model.context, CAMERA, model.lighting, "helios", antialiasing) as renderer:
        colour, ids, depth = renderer.render(view)
    assert np.array_equal(ids, frames["opengl"][0][1]) and np.array_equal(depth, frames["opengl"][0][2])
    assert np.abs(colour.astype(np.int16) - frames["helios"][0][0]).mean() <= 2.0
    assert not np.array_equal(colour, frames["opengl"][0][0])  # the option changed the colour


def test_fxaa_touches_only_silhouettes(frames: dict) -> None:
    """FXAA changes only pixels whose depth jumps by more than 2 % to a 4-neighbour: silhouettes,
    never the inside of a surface."""
    model = frames["model"]
    view = frames["views"][1]
    with open_renderer("opengl", model.context, CAMERA, model.lighting, "helios", "none") as renderer:
        plain, _, depth = renderer.render(view)
    smoothed = frames["opengl"][1][0]
    changed = (plain != smoothed).any(axis=2)
    assert 0 < changed.mean() < 0.2
    edge = np.zeros_like(changed)
    for axis in (0, 1):
        # The shader's test at the nearer pixel of a pair, a hair looser for float rounding.
        jump = np.abs(np.diff(depth, axis=axis)) > 0.019 * np.minimum(
            depth.take(range(depth.shape[axis] - 1), axis=axis), depth.take(range(1, depth.shape[axis]), axis=axis)
        )
        pad = [(0, 0), (0, 0)]
        pad[axis] = (0, 1)
        edge |= np.pad(jump, pad)
        pad[axis] = (1, 0)
        edge |= np.pad(jump, pad)
    assert not (changed & ~edge).any()


@pytest.mark.parametrize("look,antialiasing", [("helios", "none"), ("default", "none"), ("default", "fxaa")])
def test_without_depth_colour_and_ids_are_the_same(frames: dict, look: str, antialiasing: str) -> None:
    """render(depth=False) returns no depth, and the same colour and ids (with antialiasing none
    it draws with a shader that writes no depth)."""
    model = frames["model"]
    with open_renderer("opengl", model.context, CAMERA, model.lighting, look, antialiasing) as renderer:
        for view in frames["views"]:
            colour, ids, depth = renderer.render(view)
            colour2, ids2, none = renderer.render(view, depth=False)
            assert none is None and depth is not None
            assert np.array_equal(colour, colour2) and np.array_equal(ids, ids2)
            assert (ids > 0).any() and (ids == 0).any()  # plant, soil and sky in the frame


def test_renderer_and_look_choices() -> None:
    from davis_ag.errors import UserError

    assert resolve_look("opengl", None) == "default" and resolve_look("helios", None) == "helios"
    assert resolve_look("opengl", "helios") == "helios"
    for renderer, look in (("helios", "default"), ("vulkan", None), ("opengl", "blocky")):
        with pytest.raises(UserError):
            resolve_look(renderer, look)


def test_drawn_silhouettes_match_the_projected_ones(frames: dict) -> None:
    """Our renderer's count of a fruit's unoccluded pixels equals the pinhole model's."""
    from davis_ag.labels.fruit_labels import silhouette_pixels

    model = frames["model"]
    with open_renderer("opengl", model.context, CAMERA, model.lighting, "helios") as renderer:
        checked = 0
        for view in frames["views"]:
            for fruit in model.fruits:
                projected = silhouette_pixels(CAMERA, view, fruit.polygons)
                if projected < MIN_FRUIT_PIXELS:
                    continue
                drawn = renderer.silhouette_pixels(view, fruit.id, fruit.uuids)
                assert abs(drawn - projected) <= max(3, 0.01 * projected), (fruit.id, drawn, projected)
                checked += 1
    assert checked >= 3
