"""Drawn silhouettes: how many pixels an object (a fruit) would cover in a view if nothing hid it.

The denominator of a fruit's visible fraction (:mod:`davis_ag.labels.fruit_labels`). Our renderer
draws it as it draws the id image, with the same raster rule, so the two agree to the pixel; the
labels' own polygon count is the fallback for a renderer that cannot draw it (Helios's).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from davis_ag.render.projection import box_corners, screen_rect
from davis_ag.scene.camera import Camera
from davis_ag.scene.view_grid import Viewpoint


class DrawnSilhouettes:
    """Counts silhouette pixels with a renderer's GL objects; each object's triangles are looked
    up once and kept as a vertex array.

    Args:
        ctx: The renderer's moderngl context (current while :meth:`pixels` runs).
        program: The program that draws ids (its uniforms set by ``prepare``).
        vbo: The scene's vertex buffer, three vertices per triangle.
        vertex_format: The buffer's format and attribute names, as moderngl takes them.
        triangle_uuids: The primitive UUID of each triangle, in the buffer's order.
        positions: Each triangle's vertices (triangles, 3, 3), in the buffer's order.
        camera: Image size and field of view.
        prepare: Sets the program's view uniforms and binds its textures for a view.
    """

    def __init__(
        self,
        ctx: Any,
        program: Any,
        vbo: Any,
        vertex_format: tuple[str, ...],
        triangle_uuids: np.ndarray,
        positions: np.ndarray,
        camera: Camera,
        prepare: Callable[[Viewpoint], None],
    ) -> None:
        self.ctx, self.program, self.vbo, self.vertex_format = ctx, program, vbo, vertex_format
        self.triangle_uuids, self.positions, self.camera, self.prepare = triangle_uuids, positions, camera, prepare
        self._groups: dict[int, tuple | None] = {}
        self._fbo: Any = None

    def pixels(self, view: Viewpoint, key: int, uuids: np.ndarray) -> int:
        """Pixels whose centre some primitive of ``uuids`` covers with nothing else drawn. One 1x
        raster of only its triangles, the same rule the id image follows, cleared, drawn and read
        back inside the rectangle its vertices project to (a whole-frame clear and read-back cost
        ten times the raster of a small fruit). The caller makes the context current.

        Args:
            view: The pose.
            key: A name for the group (a fruit id): its triangles are looked up once.
            uuids: The group's primitive UUIDs.
        """
        import moderngl

        if key not in self._groups:
            self._groups[key] = self._group(uuids)
        group = self._groups[key]
        if group is None:
            return 0
        vao, corners = group
        rect = screen_rect(self.camera, view, corners)
        if rect is None:
            return 0
        if self._fbo is None:
            size = (self.camera.width, self.camera.height)
            self._fbo = self.ctx.framebuffer([self.ctx.renderbuffer(size, 1, dtype="u4")])
        self.prepare(view)
        fbo = self._fbo
        fbo.scissor = rect
        fbo.use()
        fbo.clear(0.0, 0.0, 0.0, 0.0, viewport=rect)
        self.ctx.disable(moderngl.DEPTH_TEST)
        vao.render(moderngl.TRIANGLES)
        self.ctx.enable(moderngl.DEPTH_TEST)
        ids = np.frombuffer(fbo.read(viewport=rect, components=1, dtype="u4"), dtype=np.uint32)
        fbo.scissor = None
        return int(np.count_nonzero(ids))

    def _group(self, uuids: np.ndarray) -> tuple | None:
        """A vertex array of the triangles of ``uuids`` and the corners of their box (whose
        projection bounds theirs), or None if none is drawn."""
        triangles = np.nonzero(np.isin(self.triangle_uuids, np.asarray(uuids, dtype=np.uint32)))[0]
        if not len(triangles):
            return None
        indices = (triangles[:, None] * 3 + np.arange(3)).astype(np.uint32)
        vao = self.ctx.vertex_array(
            self.program,
            [(self.vbo, *self.vertex_format)],
            index_buffer=self.ctx.buffer(indices.tobytes()),
            index_element_size=4,
            skip_errors=True,
        )
        return vao, box_corners(self.positions[triangles])
