"""A live scene: a generated scene reopened, drawn from any camera pose with the generator's labels.

::

    from davis_ag.live.scene import open_live_scene
    with open_live_scene("data/Single-Strawberry/000") as scene:
        view = scene.render(scene.aimed_pose(1.0, -0.5, 0.4))           # SP: aim at the plant
        view = scene.render(scene.pose(1.0, -0.5, 0.4, yaw=150, pitch=-10), width=640, height=360)
        view.boxes, view.oer, view.visible_fraction, view.depth

Conventions are scene.json's (world metres, yaw counter-clockwise from +x, pitch above the
horizon); boxes and segmentation follow :mod:`davis_ag.labels.fruit_labels`, with the crop's box
threshold (section III-C) scaled by image area as the generator scales it. A pose of the grid
(:meth:`LiveScene.grid_view`) drawn at the scene's own size and settings gives the stored view.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from davis_ag.formats.layout import view_name
from davis_ag.generate.recorded_settings import RecordedSettings, read_settings
from davis_ag.labels.fruit_labels import fruit_lookup, label_view, visible_fractions
from davis_ag.live.reopen import SceneAssets, reopen_assets
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import plant_centres
from davis_ag.scene.view_grid import Viewpoint

if TYPE_CHECKING:  # the renderer loads OpenGL: imported where the first one is made
    from davis_ag.render.opengl import OpenGLRenderer


@dataclass(frozen=True)
class LiveView:
    """One view drawn live, labelled as the generator labels its views.

    Attributes:
        pose: ``[x, y, z, yaw, pitch]`` (m, degrees).
        colour: (height, width, 3) uint8 RGB, row 0 at the top.
        segmentation: (height, width) fruit id per pixel for boxed fruit, no fruit elsewhere: uint8
            with 255, or uint16 with 65535 in a scene of more than 255 fruit (:mod:`davis_ag.formats.masks`).
        boxes: ``[xmin, ymin, width, height, fruit_id, 0]`` per fruit above the threshold.
        visible_pixels: Visible pixels of each boxed fruit.
        oer: Object exposure rate (eq. 1, section V-A) of each boxed fruit.
        visible_fraction: Visible over unoccluded pixels of each boxed fruit (None when not asked).
        depth: (height, width) float32, metres along the optical axis, 0 where nothing is hit (None
            when not asked).
    """

    pose: list[float]
    colour: np.ndarray
    segmentation: np.ndarray
    boxes: list[list[int]]
    visible_pixels: dict[int, int]
    oer: dict[int, float]
    visible_fraction: dict[int, float] | None
    depth: np.ndarray | None

    def box(self, fruit_id: int) -> list[int] | None:
        """The fruit's box in this view, or None."""
        return next((b for b in self.boxes if b[4] == fruit_id), None)


def exposure_rates(labels_boxes: list[list[int]], visible_pixels: dict[int, int]) -> dict[int, float]:
    """Eq. 1: a fruit's pixels inside its box over the box's area (its box is its pixels' extent)."""
    return {b[4]: visible_pixels[b[4]] / float(b[2] * b[3]) for b in labels_boxes}


def min_pixels_for(settings: RecordedSettings, width: int, height: int) -> int:
    """The box threshold at an image size: scene.json's at its own size, else the crop's scaled."""
    if (width, height) == (
        settings.camera.width,
        settings.camera.height,
    ) and settings.metadata.min_fruit_pixels is not None:
        return settings.metadata.min_fruit_pixels
    return settings.crop.min_fruit_pixels_at(width, height)


def merge_ground(geometry):
    """The scene with its soil (every non-caster triangle: 10,000 near patches and the far ring) as
    two triangles, where that draws the same image: soil of one texture and colour, drawn in the
    default look (which lays the soil texture by world position, not by the tiles' coordinates).
    Ids and depth of fruit and leaves do not change; the soil's id becomes its first tile's.

    Returns:
        A :class:`~davis_ag.render.scene_geometry.SceneGeometry` (``geometry`` itself when the
        soil cannot be merged).
    """
    from davis_ag.render.scene_geometry import SceneGeometry

    ground = ~geometry.caster
    if (
        ground.sum() <= 2
        or len(np.unique(geometry.texture[ground])) != 1
        or len(np.unique(geometry.colours[ground], axis=0)) != 1
    ):
        return geometry
    first = int(np.flatnonzero(ground)[0])
    lo = geometry.positions[ground].reshape(-1, 3).min(axis=0)
    hi = geometry.positions[ground].reshape(-1, 3).max(axis=0)
    corners = np.array(
        [[lo[0], lo[1], 0.0], [hi[0], lo[1], 0.0], [hi[0], hi[1], 0.0], [lo[0], hi[1], 0.0]], dtype=np.float32
    )
    quad = corners[[[0, 1, 2], [0, 2, 3]]]
    keep = np.flatnonzero(~ground)
    pick = np.concatenate([keep, [first, first]])

    def merged(values: np.ndarray, extra: np.ndarray | None = None) -> np.ndarray:
        out = values[pick].copy()
        if extra is not None:
            out[-2:] = extra
        return out

    return SceneGeometry(
        positions=merged(geometry.positions, quad),
        uvs=merged(geometry.uvs, np.zeros((2, 3, 2), np.float32)),
        normals=merged(geometry.normals, np.tile(np.float32([0, 0, 1]), (2, 3, 1))),
        uuids=merged(geometry.uuids),
        colours=merged(geometry.colours),
        texture=merged(geometry.texture),
        mode=merged(geometry.mode),
        caster=merged(geometry.caster),
        patch=merged(geometry.patch),
        texture_files=list(geometry.texture_files),
    )


class LiveScene:
    """A reopened scene; draw it with :meth:`render`. Holds one renderer per image size."""

    def __init__(self, settings: RecordedSettings, assets: SceneAssets) -> None:
        """Args:
        settings: The scene's scene.json settings.
        assets: Its geometry, fruit and grid (:func:`davis_ag.live.reopen.reopen_assets`).
        """
        self.settings, self.assets = settings, assets
        self.lookup = fruit_lookup(assets.fruit_uuids, assets.uuid_count)
        self._renderers: dict[tuple[Camera, str, bool], OpenGLRenderer] = {}
        self._names = {view_name(v.number): v for v in assets.grid_views}

    # ------------------------------------------------------------------------------ poses

    @property
    def stems(self) -> np.ndarray:
        """(n, 2) plant stem positions, m."""
        return np.asarray([c[:2] for c in plant_centres(self.settings.scenario, self.settings.crop)])

    @property
    def aim_point(self) -> tuple[float, float, float]:
        """Where single-plant cameras aim: the plant at the origin, at its aim height."""
        return (0.0, 0.0, self.assets.aim_height)

    @staticmethod
    def pose(x: float, y: float, z: float, yaw: float, pitch: float) -> Viewpoint:
        """A free camera pose (m, degrees)."""
        position = (float(x), float(y), float(z))
        return Viewpoint(-1, 0, 0, 0, 0, position, position, float(yaw), float(pitch))

    def aimed_pose(self, x: float, y: float, z: float, target: tuple[float, float, float] | None = None) -> Viewpoint:
        """A pose at (x, y, z) looking at ``target`` (default the plant, as single-plant views do)."""
        tx, ty, tz = target if target is not None else self.aim_point
        dx, dy, dz = tx - x, ty - y, tz - z
        return self.pose(x, y, z, math.degrees(math.atan2(dy, dx)), math.degrees(math.atan2(dz, math.hypot(dx, dy))))

    def grid_view(self, image_name: str) -> Viewpoint:
        """The exact pose of a stored view (``"0001.jpeg"``).

        Raises:
            KeyError: for a name not in the grid.
        """
        return self._names[image_name]

    @property
    def grid_views(self) -> list[Viewpoint]:
        """Every stored view's pose, in image order."""
        return list(self.assets.grid_views)

    # ------------------------------------------------------------------------------ drawing

    def renderer(
        self,
        width: int,
        height: int,
        vfov: float | None = None,
        antialiasing: str | None = None,
        fast_ground: bool = False,
    ) -> OpenGLRenderer:
        """The renderer for an image size (made once, kept until :meth:`close`); ``fast_ground``
        draws the soil as one quad (:func:`merge_ground`)."""
        from davis_ag.render.backends import resolve_antialiasing

        settings = self.settings
        camera = Camera(int(width), int(height), float(vfov if vfov is not None else settings.camera.vfov))
        aa = resolve_antialiasing(settings.antialiasing if antialiasing is None else antialiasing)
        key = (camera, aa, fast_ground)
        if key not in self._renderers:
            from davis_ag.render.opengl import OpenGLRenderer

            geometry = self.assets.geometry
            if fast_ground and settings.look == "default":
                geometry = merge_ground(geometry)
            self._renderers[key] = OpenGLRenderer(
                geometry, camera, self.assets.lighting, look=settings.look, antialiasing=aa
            )
        return self._renderers[key]

    def render(
        self,
        view: Viewpoint,
        width: int | None = None,
        height: int | None = None,
        vfov: float | None = None,
        antialiasing: str | None = None,
        fractions: bool = True,
        fast_ground: bool = False,
        depth: bool = True,
    ) -> LiveView:
        """Draw and label one pose.

        Args:
            view: The pose (:meth:`pose`, :meth:`aimed_pose`, :meth:`grid_view`).
            width, height: Image size (default the scene's own).
            vfov: Vertical field of view, degrees (default the scene's).
            antialiasing: ``fxaa``, ``msaa`` or ``none`` (default the scene's); ids are exact in every mode.
            fractions: Also count each boxed fruit's unoccluded pixels (one small pass per fruit).
            fast_ground: Draw the soil as one quad (:func:`merge_ground`): the same image for
                fewer triangles; off by default so that a grid pose redraws exactly as stored.
            depth: Also return the depth image (False: ``depth`` is None, and with antialiasing
                ``none`` the renderer skips drawing it; colour and labels are the same).

        Returns:
            The :class:`LiveView`.
        """
        width = int(width or self.settings.camera.width)
        height = int(height or self.settings.camera.height)
        renderer = self.renderer(width, height, vfov, antialiasing, fast_ground)
        colour, ids, depth_image = renderer.render(view, depth=depth)
        labels = label_view(ids, self.lookup, min_pixels_for(self.settings, width, height))
        visible = None
        if fractions:
            uuids = self.assets.fruit_uuids
            visible = visible_fractions(
                renderer.camera, view, labels, {}, lambda fruit: renderer.silhouette_pixels(view, fruit, uuids[fruit])
            )
        return LiveView(
            [*view.position, view.yaw, view.pitch],
            colour,
            labels.segmentation,
            labels.boxes,
            labels.visible_pixels,
            exposure_rates(labels.boxes, labels.visible_pixels),
            visible,
            depth_image,
        )

    def close(self) -> None:
        """Release every renderer."""
        for renderer in self._renderers.values():
            renderer.close()
        self._renderers.clear()

    def __enter__(self) -> LiveScene:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def open_live_scene(scene_dir: str | Path, use_cache: bool = True) -> LiveScene:
    """Reopen a scene made by ``davis-ag generate`` (seconds from its cache; a regrow otherwise).

    Args:
        scene_dir: The scene folder (``<root>/<group>/<NNN>``).
        use_cache: False regrows even where a current geometry cache exists.

    Raises:
        UserError: when the folder holds no scene of ours or it does not regrow as stored.
    """
    settings = read_settings(scene_dir)
    return LiveScene(settings, reopen_assets(settings, use_cache))
