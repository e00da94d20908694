"""The pinhole camera model and the Helios renderer agree on where things land in the image."""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from davis_ag.labels.fruit_labels import silhouette_pixels
from davis_ag.render.helios import HeliosRenderer
from davis_ag.scene.camera import Camera
from davis_ag.scene.lighting import Lighting
from davis_ag.scene.view_grid import Viewpoint
from helios_reference import helios_reference

CAMERA = Camera(96, 54)
#: Two poses looking roughly along +x, one level and one turned, raised and tilted down.
VIEWS = (
    Viewpoint(0, 0, 0, 0, 0, (0.0, 0.0, 1.0), (0.0, 0.0, 1.0), 5.0, -2.0),
    Viewpoint(1, 0, 0, 0, 0, (0.0, 0.0, 1.0), (0.2, -0.5, 1.6), 20.0, -14.0),
)
#: Centres and radii of the spheres in the scene, m: each view sees both, off the image centre.
SPHERES = (((2.0, 0.3, 1.1), 0.12), ((2.3, -0.2, 0.8), 0.08))


def pose(position: tuple[float, float, float], yaw: float, pitch: float) -> Viewpoint:
    return Viewpoint(0, 0, 0, 0, 0, position, position, yaw, pitch)


@pytest.fixture(scope="module")
def scene() -> Iterator[tuple[HeliosRenderer, list[np.ndarray], list[list[np.ndarray]]]]:
    """A renderer over two red spheres on a grey ground, with their UUIDs and triangles."""
    from davis_ag.scene.plants import primitive_vertices, require_native_helios

    require_native_helios()
    from pyhelios import Context
    from pyhelios.types import RGBcolor, vec2, vec3

    context = Context()
    uuids, polygons = [], []
    for centre, radius in SPHERES:
        obj = context.addSphereObject(vec3(*centre), radius, 20, RGBcolor(0.9, 0.1, 0.1))
        ids = np.asarray(context.getObjectPrimitiveUUIDs(obj))
        uuids.append(ids)
        parts = primitive_vertices(context, list(ids))
        polygons.append([np.stack([p for p in parts if len(p) == k]) for k in sorted({len(p) for p in parts})])
    context.addPatch(vec3(0.0, 0.0, 0.0), vec2(20.0, 20.0), color=RGBcolor(0.5, 0.5, 0.5))
    with HeliosRenderer(context, CAMERA, Lighting(sun_elevation=60.0, sun_azimuth=30.0)) as renderer:
        yield renderer, uuids, polygons


def test_intrinsics_are_consistent() -> None:
    camera = Camera(1280, 720)
    k = camera.intrinsics()
    assert k["fx"] == k["fy"] == pytest.approx(360 / math.tan(math.radians(22.5)))
    assert (k["cx"], k["cy"], k["width"], k["height"]) == (640, 360, 1280, 720)
    aspect_hfov = math.degrees(2 * math.atan(math.tan(math.radians(k["vfov_deg"] / 2)) * 1280 / 720))
    assert k["hfov_deg"] == pytest.approx(aspect_hfov)
    assert k["hfov_deg"] == pytest.approx(math.degrees(2 * math.atan(k["cx"] / k["fx"])))
    assert Camera(96, 54).hfov == pytest.approx(camera.hfov)  # same aspect, same field of view


@settings(max_examples=100, deadline=None)
@given(
    st.tuples(st.floats(-3, 3), st.floats(-3, 3), st.floats(0.1, 2)),
    st.floats(-180, 180),
    st.floats(-80, 80),
    st.floats(-0.4, 0.4),
    st.floats(-0.2, 0.2),
    st.floats(0.3, 5.0),
)
def test_projection_inverts_the_pinhole_model(
    position: tuple[float, float, float],
    yaw: float,
    pitch: float,
    right: float,
    up: float,
    depth: float,
) -> None:
    view = pose(position, yaw, pitch)
    centre, distance = CAMERA.project(view, np.array(view.look_at(depth)))
    assert centre == pytest.approx([CAMERA.width / 2, CAMERA.height / 2], abs=1e-6)
    assert distance == pytest.approx(depth)
    # A point offset sideways and upwards, in the camera's own frame, lands fy * offset / depth away.
    forward = np.subtract(view.look_at(1.0), position)
    side = np.cross(forward, (0.0, 0.0, 1.0))
    side /= np.linalg.norm(side)
    above = np.cross(side, forward)
    point = np.asarray(view.look_at(depth)) + right * depth * side + up * depth * above
    (u, v), distance = CAMERA.project(view, point)
    assert distance == pytest.approx(depth)
    assert u == pytest.approx(CAMERA.width / 2 + CAMERA.fy * right, abs=1e-6)
    assert v == pytest.approx(CAMERA.height / 2 - CAMERA.fy * up, abs=1e-6)


@helios_reference
@pytest.mark.parametrize("view", VIEWS, ids=["level", "tilted"])
def test_spheres_render_where_the_camera_model_projects_them(scene, view: Viewpoint) -> None:  # type: ignore[no-untyped-def]
    renderer, uuids, polygons = scene
    renderer.set_view(view)
    ids = renderer.draw_primitive_ids()
    assert ids.shape == (CAMERA.height, CAMERA.width) and ids.dtype == np.uint32
    for (centre, radius), mine, polys in zip(SPHERES, uuids, polygons):
        mask = np.isin(ids, mine + 1)
        rows, cols = np.nonzero(mask)
        (u, v), depth = CAMERA.project(view, np.array(centre))
        expected_area = math.pi * (CAMERA.fy * radius / depth) ** 2
        assert 15 < mask.sum() == pytest.approx(expected_area, rel=0.3)  # a few pixels across
        # Pixel (u, v) covers [u, u + 1) x [v, v + 1): the centroid of the pixels is +0.5 off.
        assert cols.mean() + 0.5 == pytest.approx(u, abs=1.0)
        assert rows.mean() + 0.5 == pytest.approx(v, abs=1.0)
        # Nothing in front of it: the silhouette the labels compute matches the visible pixels.
        assert silhouette_pixels(CAMERA, view, polys) == pytest.approx(mask.sum(), abs=3)


@helios_reference
def test_id_pass_then_read_colour_equals_a_colour_draw(scene) -> None:  # type: ignore[no-untyped-def]
    renderer, _, _ = scene
    first, other = VIEWS
    renderer.set_view(first)
    ids = renderer.draw_primitive_ids()
    colour = renderer.read_colour()
    renderer.set_view(other)
    elsewhere = renderer.draw_colour()
    renderer.set_view(first)
    again = renderer.draw_colour()
    assert colour.shape == (CAMERA.height, CAMERA.width, 3) and colour.dtype == np.uint8
    assert np.array_equal(colour, again)
    assert not np.array_equal(colour, elsewhere)
    # render() is the same pair from one call.
    colour2, ids2, _ = renderer.render(first, depth=False)
    assert np.array_equal(colour2, colour) and np.array_equal(ids2, ids)
    # The spheres are red where the ids say so; the top row is sky, not ground.
    red = colour[np.isin(ids, np.concatenate(scene[1]) + 1)].astype(int)
    assert (red[:, 0] > red[:, 1] + 40).mean() > 0.9
    assert (ids[0] == 0).all()
