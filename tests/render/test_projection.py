"""The screen rectangle that bounds an object's silhouette: the drawn silhouette counts pixels only
inside it, so a pixel it missed would be lost from a fruit's visible fraction."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from davis_ag.render.projection import box_corners, screen_rect
from davis_ag.scene.camera import Camera
from davis_ag.scene.view_grid import Viewpoint

CAMERA = Camera(320, 180)


def viewpoint(yaw: float, pitch: float) -> Viewpoint:
    return Viewpoint(0, 0, 0, 0, 0, (0.0, 0.0, 1.0), (0.0, 0.0, 1.0), yaw, pitch)


coordinate = st.floats(-3.0, 3.0, allow_nan=False)


@settings(max_examples=200, deadline=None)
@given(
    yaw=st.floats(0.0, 359.0),
    pitch=st.floats(-60.0, 60.0),
    points=st.lists(st.tuples(coordinate, coordinate, coordinate), min_size=1, max_size=6),
)
def test_the_rectangle_holds_every_pixel_its_box_projects_to(yaw: float, pitch: float, points: list) -> None:
    view = viewpoint(yaw, pitch)
    world = np.asarray(points) + np.array([0.0, 0.0, 1.0])
    corners = box_corners(world)
    rect = screen_rect(CAMERA, view, corners)
    pixels, depth = CAMERA.project(view, corners[:, :3])
    if (depth <= 0.2).any():  # a corner near or behind the eye: no finite rectangle is promised
        return
    u, v = pixels[:, 0], CAMERA.height - pixels[:, 1]  # OpenGL's rows count from the bottom
    inside = (u >= 0) & (u <= CAMERA.width) & (v >= 0) & (v <= CAMERA.height)
    if rect is None:
        assert not inside.any()
        return
    x, y, w, h = rect
    assert 0 <= x and 0 <= y and x + w <= CAMERA.width and y + h <= CAMERA.height and w > 0 and h > 0
    assert (u[inside] >= x).all() and (u[inside] <= x + w).all()
    assert (v[inside] >= y).all() and (v[inside] <= y + h).all()


def test_a_box_behind_the_eye_takes_the_whole_frame_and_one_off_screen_none() -> None:
    view = viewpoint(0.0, 0.0)  # looking along +x
    behind = box_corners(np.array([[-1.0, -0.1, 0.9], [-0.5, 0.1, 1.1]]))
    assert screen_rect(CAMERA, view, behind) == (0, 0, CAMERA.width, CAMERA.height)
    far_left = box_corners(np.array([[1.0, 5.0, 0.9], [1.2, 5.2, 1.1]]))  # 79 degrees off the axis
    assert screen_rect(CAMERA, view, far_left) is None
    ahead = box_corners(np.array([[2.0, -0.05, 0.95], [2.1, 0.05, 1.05]]))
    x, y, w, h = screen_rect(CAMERA, view, ahead)
    assert x < CAMERA.width / 2 < x + w and y < CAMERA.height / 2 < y + h and w < CAMERA.width / 4
