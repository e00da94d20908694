"""Our renderer draws randomised appearance (sun strength, exposure, white balance, sensor noise)
in the same pass as before: ids and depth never change, colours change as asked."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import replace

import numpy as np
import pytest

from davis_ag.scene.camera import Camera
from davis_ag.scene.lighting import Lighting
from davis_ag.scene.view_grid import Viewpoint

CAMERA = Camera(192, 108)
PAPER = Lighting(sun_elevation=60.0, sun_azimuth=30.0)
#: Looking down at the soil from 1 m, the horizon and sky in the top of the frame.
VIEWS = [Viewpoint(i, 0, 0, 0, 0, (0.0, -2.0 + i, 1.0), (0.0, -2.0 + i, 1.0), 90.0, -15.0) for i in range(2)]


@pytest.fixture(scope="module")
def soil_context() -> Iterator[object]:
    """A Context holding the scene's soil and one red ball (no plant to grow)."""
    from pyhelios import Context
    from pyhelios.types import RGBcolor, vec3

    from davis_ag.scene.build import add_ground
    from davis_ag.scene.plants import require_native_helios

    require_native_helios()
    context = Context()
    add_ground(context)
    context.addSphere(ndivs=12, center=vec3(0.0, 0.0, 0.3), radius=0.15, color=RGBcolor(0.8, 0.1, 0.1))
    yield context


def draw(context, lighting: Lighting, view: Viewpoint = VIEWS[0]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    from davis_ag.render.opengl import OpenGLRenderer

    with OpenGLRenderer(context, CAMERA, lighting, antialiasing="none") as renderer:
        return renderer.render(view)


def test_soil_is_labelled_soil(soil_context) -> None:
    from davis_ag.scene.build import SceneModel
    from davis_ag.scene.organs import SOIL

    table = SceneModel(soil_context, [], [], PAPER, 0.0).organ_of_uuid()
    labels = table[np.asarray(soil_context.getAllUUIDs())]
    assert set(labels.tolist()) == {SOIL, 0} and (labels == SOIL).sum() > 10_000  # the ball is unlabelled


def test_sensor_noise_is_gaussian_fixed_per_view_and_new_for_each_view(soil_context) -> None:
    clean, ids, depth = draw(soil_context, PAPER)
    noisy = replace(PAPER, noise_sigma=3.0, noise_seed=5)
    first, ids_noisy, depth_noisy = draw(soil_context, noisy)
    again = draw(soil_context, noisy)[0]
    assert np.array_equal(ids, ids_noisy) and np.array_equal(depth, depth_noisy)
    assert np.array_equal(first, again)
    inside = (clean > 12) & (clean < 243)  # away from the clamp at 0 and 255
    difference = (first.astype(float) - clean)[inside]
    assert abs(difference.mean()) < 0.15 and difference.std() == pytest.approx(3.0, rel=0.1)
    other_view = draw(soil_context, noisy, VIEWS[1])[0].astype(float) - draw(soil_context, PAPER, VIEWS[1])[0]
    other_seed = draw(soil_context, replace(noisy, noise_seed=6))[0].astype(float) - clean
    for pattern in (other_view, other_seed):
        assert abs(np.corrcoef(pattern[inside].ravel(), difference.ravel())[0, 1]) < 0.05


def test_exposure_white_balance_and_sun_strength_change_colour_only(soil_context) -> None:
    clean, ids, depth = draw(soil_context, PAPER)
    soil = ids > 0  # and the ball
    mean = clean[soil].reshape(-1, 3).mean(axis=0)
    for change, check in (
        ({"exposure": 1.5}, lambda m: (m > mean + 5).all()),
        ({"sun_strength": 0.5}, lambda m: (m < mean - 5).all()),
        (
            {"white_balance": (1.15, 1.0, 0.85)},
            lambda m: m[0] > mean[0] + 3 and m[2] < mean[2] - 3 and abs(m[1] - mean[1]) < 1,
        ),
    ):
        colour, ids2, depth2 = draw(soil_context, replace(PAPER, **change))
        assert np.array_equal(ids, ids2) and np.array_equal(depth, depth2)
        assert check(colour[soil].reshape(-1, 3).mean(axis=0)), change
