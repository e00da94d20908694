"""Draw views of a Helios scene with pyhelios's Visualizer: colour, primitive ids and depth from
native buffers. The reference backend (``--renderer helios``); :mod:`davis_ag.render.opengl` is ours.

The camera (:mod:`davis_ag.scene.camera`) is an ideal pinhole. Helios' field of view is vertical; pixel (column u, row v) covers
[u, u+1) x [v, v+1) with row 0 at the top, so a point at camera coordinates (right, up, forward)
lands at u = cx + fx * right / forward, v = cy - fy * up / forward with cx = width / 2,
cy = height / 2 (measured against rendered spheres to within half a pixel).
"""

from __future__ import annotations

import ctypes

import numpy as np

from davis_ag.scene.camera import Camera
from davis_ag.scene.lighting import Lighting
from davis_ag.scene.view_grid import Viewpoint


class HeliosRenderer:
    """A headless Helios Visualizer holding one scene's geometry.

    Args:
        context: The Helios Context with the scene.
        camera: Image size and field of view.
        lighting: Sun direction and sky.
        antialiasing: Multisamples of the colour image (ids are always exact).
    """

    def __init__(self, context, camera: Camera, lighting: Lighting, antialiasing: int = 4) -> None:
        from pyhelios import Visualizer
        from pyhelios.types import vec3

        from davis_ag.scene.plants import quiet_stdout

        self.camera = camera
        self._vec3 = vec3
        with quiet_stdout():
            self._vis = Visualizer(camera.width, camera.height, antialiasing_samples=antialiasing, headless=True)
        self._vis.hideWatermark()
        self._vis.hideNavigationGizmo()
        self._vis.disableMessages()
        self._vis.setCameraFieldOfView(camera.vfov)
        self._vis.setLightingModel("phong_shadowed")
        self._vis.setLightDirection(vec3(*lighting.direction))
        self._vis.setBackgroundSkyTexture(lighting.sky_texture)
        self._vis.buildContextGeometry(context)
        # The very first frame is drawn before the shadow map exists; draw one to throw away.
        self._vis.plotOnce(False)

    def set_view(self, view: Viewpoint) -> None:
        """Place the camera at a viewpoint."""
        self._vis.setCameraPosition(self._vec3(*view.position), self._vec3(*view.look_at(1.0)))

    def draw_colour(self) -> np.ndarray:
        """Draw the colour image of the current view, (height, width, 3) uint8, row 0 at the top."""
        self._vis.plotOnce(False)
        return self.read_colour()

    def read_colour(self) -> np.ndarray:
        """The colour image last drawn, without drawing again."""
        from pyhelios.plugins import helios_lib

        width, height, size = ctypes.c_uint(), ctypes.c_uint(), ctypes.c_uint()
        pointer = helios_lib.getWindowPixelsRGB_sized(
            self._vis.visualizer, ctypes.byref(width), ctypes.byref(height), ctypes.byref(size)
        )
        self._check(pointer, size.value)
        # The native buffer is bottom row first, one uint32 per channel.
        pixels = np.ctypeslib.as_array(pointer, shape=(size.value,)).reshape(height.value, width.value, 3)
        return pixels[::-1].astype(np.uint8)

    def draw_primitive_ids(self) -> np.ndarray:
        """Draw which primitive each pixel sees: UUID + 1, 0 for none, (height, width) uint32.

        Helios draws the colour frame first as part of this call, so :meth:`read_colour` then
        returns the colour image of the same view with no second draw.
        """
        from pyhelios.plugins import helios_lib

        width, height, size = ctypes.c_uint(), ctypes.c_uint(), ctypes.c_uint()
        pointer = helios_lib.visualizerGetPixelUUIDs(
            self._vis.visualizer, ctypes.byref(width), ctypes.byref(height), ctypes.byref(size)
        )
        self._check(pointer, size.value)
        return np.ctypeslib.as_array(pointer, shape=(size.value,)).reshape(height.value, width.value).copy()

    def read_depth(self) -> np.ndarray:
        """Depth of the current view along the optical axis, metres, 0 where nothing is hit,
        (height, width) float32, row 0 at the top (Helios's annotation pass)."""
        from pyhelios.plugins import helios_lib

        width, height, size = ctypes.c_uint(), ctypes.c_uint(), ctypes.c_uint()
        pointer = helios_lib.visualizerGetDepthImage(
            self._vis.visualizer, ctypes.byref(width), ctypes.byref(height), ctypes.byref(size)
        )
        self._check(pointer, size.value)
        depth = np.ctypeslib.as_array(pointer, shape=(size.value,)).reshape(height.value, width.value)
        return np.where(depth > 0, depth, 0).astype(np.float32)

    def render(self, view: Viewpoint, depth: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """Colour image, primitive ids and depth of one view (depth None when not asked for).

        The colour and id passes are drawn once each; the depth comes from one more Helios call.
        """
        self.set_view(view)
        primitive_ids = self.draw_primitive_ids()
        colour = self.read_colour()
        return colour, primitive_ids, self.read_depth() if depth else None

    def close(self) -> None:
        """Release the Visualizer and its GL context."""
        vis, self._vis = self._vis, None
        if vis is not None:
            del vis

    def _check(self, pointer, size: int) -> None:
        expected = self.camera.width * self.camera.height
        if not pointer or size not in (expected, 3 * expected):
            raise RuntimeError(f"Helios returned {size} values for a {self.camera.width}x{self.camera.height} view")

    def __enter__(self) -> HeliosRenderer:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
