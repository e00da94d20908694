"""The dataset's cameras as 4x4 camera-to-world matrices in the OpenGL convention.

A view's pose is ``[x, y, z, yaw, pitch]`` (world metres, Z up, degrees; :mod:`davis_ag.scene.camera`):
the camera looks along ``forward``, its image's right is ``forward x Z`` and its up is
``right x forward``. USD cameras and nerfstudio's ``transforms.json`` both use OpenGL's camera
frame (+x right, +y up, looking down -z), so the matrix's columns are ``right``, ``up``,
``-forward`` and the position.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from davis_ag.data.point_cloud import camera_axes


def camera_to_world(pose: Sequence[float]) -> np.ndarray:
    """The OpenGL camera-to-world matrix of a pose.

    Args:
        pose: ``[x, y, z, yaw, pitch]`` (m, degrees), as annotations.json records it.

    Returns:
        (4, 4) float64: columns right, up, back (``-forward``) and the camera's position.
    """
    forward, right, up = camera_axes(tuple(float(v) for v in pose))
    matrix = np.eye(4)
    matrix[:3, 0], matrix[:3, 1], matrix[:3, 2] = right, up, -forward
    matrix[:3, 3] = [float(v) for v in pose[:3]]
    return matrix + 0.0  # no -0.0 in the files
