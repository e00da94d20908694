"""The exports' camera-to-world matrices against the renderer's own projection, for any pose."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from davis_ag.scene.camera import Camera
from davis_ag.scene.view_grid import Viewpoint
from davis_ag.worlds.cameras import camera_to_world

coordinate = st.floats(-5.0, 5.0, allow_nan=False)


@given(
    position=st.tuples(coordinate, coordinate, st.floats(0.05, 3.0)),
    yaw=st.floats(-180.0, 180.0),
    pitch=st.floats(-85.0, 85.0),
    point=st.tuples(coordinate, coordinate, st.floats(0.0, 2.0)),
    size=st.sampled_from([(160, 90), (1280, 720), (96, 96)]),
)
def test_an_opengl_camera_sees_a_point_where_the_renderer_draws_it(position, yaw, pitch, point, size) -> None:
    matrix = camera_to_world([*position, yaw, pitch])
    rotation = matrix[:3, :3]
    assert np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-9) and np.isclose(np.linalg.det(rotation), 1.0)
    assert rotation[2, 1] >= -1e-9  # the image's up never points down (the camera does not roll)
    camera = Camera(*size)
    view = Viewpoint(0, 0, 0, 0, 0, position, position, yaw, pitch)
    (u, v), depth = camera.project(view, np.asarray(point))
    local = rotation.T @ (np.asarray(point) - matrix[:3, 3])  # +x right, +y up, +z back
    assert np.isclose(-local[2], depth, atol=1e-9)
    if depth > 0.1:
        fx = camera.fy  # square pixels; principal point at the centre (pixel centres at +0.5)
        assert np.isclose(camera.width / 2 + fx * local[0] / depth, u, atol=1e-6)
        assert np.isclose(camera.height / 2 - fx * local[1] / depth, v, atol=1e-6)
