"""The pinhole camera: intrinsics and projection of world points into a view (pure geometry).

The camera is an ideal pinhole. Helios' field of view is vertical; pixel (column u, row v) covers
[u, u+1) x [v, v+1) with row 0 at the top, so a point at camera coordinates (right, up, forward)
lands at u = cx + fx * right / forward, v = cy - fy * up / forward with cx = width / 2,
cy = height / 2 (measured against rendered spheres to within half a pixel).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from davis_ag.scene.view_grid import Viewpoint

#: Vertical field of view of every camera, degrees (horizontal follows from the aspect ratio).
DEFAULT_VFOV = 45.0


@dataclass(frozen=True)
class Camera:
    """Image size and field of view of the pinhole camera.

    Attributes:
        width, height: Image size in pixels.
        vfov: Vertical field of view, degrees.
    """

    width: int = 1280
    height: int = 720
    vfov: float = DEFAULT_VFOV

    @property
    def fy(self) -> float:
        """Focal length in pixels (square pixels, so also fx)."""
        return (self.height / 2) / math.tan(math.radians(self.vfov) / 2)

    @property
    def hfov(self) -> float:
        """Horizontal field of view, degrees."""
        return math.degrees(2 * math.atan((self.width / 2) / self.fy))

    def intrinsics(self) -> dict:
        """JSON-ready intrinsics, in the OpenCV convention (pixel centres at +0.5)."""
        return {
            "model": "pinhole",
            "width": self.width,
            "height": self.height,
            "fx": self.fy,
            "fy": self.fy,
            "cx": self.width / 2,
            "cy": self.height / 2,
            "vfov_deg": self.vfov,
            "hfov_deg": self.hfov,
            "distortion": [0.0, 0.0, 0.0, 0.0, 0.0],
        }

    def project(self, view: Viewpoint, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Project world points into a view.

        Args:
            view: The camera pose.
            points: World points, (..., 3).

        Returns:
            Pixel coordinates (..., 2) as (u, v) and depth along the optical axis (...).
        """
        forward = np.asarray(view.look_at(1.0)) - np.asarray(view.position)
        forward /= np.linalg.norm(forward)
        right = np.cross(forward, (0.0, 0.0, 1.0))
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        offset = np.asarray(points, dtype=np.float64) - np.asarray(view.position)
        depth = offset @ forward
        safe = np.where(depth > 1e-6, depth, 1e-6)
        u = self.width / 2 + self.fy * (offset @ right) / safe
        v = self.height / 2 - self.fy * (offset @ up) / safe
        return np.stack([u, v], axis=-1), depth
