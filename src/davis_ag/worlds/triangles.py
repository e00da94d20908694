"""A generated scene's triangles with their labels: what every 3-D export writes.

The geometry is the live scene's (:mod:`davis_ag.live.reopen`: ``live_geometry.npz`` in the scene
folder, or a regrow from scene.json the first time, 20-60 s a plant, checked against what scene.json
records). Each triangle gets the labels the generator's images get: its primitive's organ class
(the class table of :mod:`davis_ag.scene.organs`, whatever classes it holds), the fruit id of a fruit
body (the id of the masks and boxes; the calyx and stalk are ``stem``) and the plant it belongs to
(scene.json's plant index; -1 for the soil and anything else of no plant).

Colours are Helios's: a primitive's own colour (sRGB values in [0, 1]) or, where its texture
gives the colour, the texel at the triangle's centroid (the texture's mean opaque colour where that
texel is transparent, as at a leaf's cut-out edge).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from davis_ag.data.reader import Scene, open_dataset
from davis_ag.errors import UserError
from davis_ag.formats.layout import SCENE_METADATA
from davis_ag.generate.recorded_settings import read_settings
from davis_ag.live.reopen import reopen_assets
from davis_ag.render.scene_geometry import TEXTURE, SceneGeometry
from davis_ag.scene.organs import ORGAN_NAMES

#: Fruit id and plant of a triangle that is no fruit body, or of no plant.
NONE = -1


@dataclass(frozen=True)
class WorldTriangles:
    """A scene's triangles, three corners each, in world metres (Z up), with their labels.

    Attributes:
        scene: The dataset's scene.
        geometry: The triangles as the renderer draws them (positions, normals, texture
            coordinates, textures, Helios colours).
        organ: (n,) uint8 organ class of each triangle (an index into :attr:`class_names`).
        fruit: (n,) int32 fruit id of each fruit-body triangle, :data:`NONE` elsewhere.
        plant: (n,) int32 plant index of each triangle, :data:`NONE` for no plant.
        rgb: (n, 3) uint8 sRGB colour of each triangle (:func:`face_colours`).
        class_names: The organ class table, by value.
    """

    scene: Scene
    geometry: SceneGeometry
    organ: np.ndarray
    fruit: np.ndarray
    plant: np.ndarray
    rgb: np.ndarray
    class_names: tuple[str, ...]

    @property
    def count(self) -> int:
        """How many triangles."""
        return len(self.organ)

    def class_name(self, value: int) -> str:
        """The name of an organ class value (``class_<value>`` for one the table lacks)."""
        return self.class_names[value] if 0 <= value < len(self.class_names) else f"class_{value}"


def geometry_scenes(path: str | Path, export: str) -> list[Scene]:
    """The scenes under ``path``, each checked to be one ``davis-ag generate`` made.

    Args:
        path: A dataset root, group folder or scene folder.
        export: The export's name, for the message.

    Raises:
        UserError: naming the first scene without scene.json (the original download's layout).
    """
    scenes = open_dataset(path).scenes
    for scene in scenes:
        if not (scene.path / SCENE_METADATA).is_file():
            raise UserError(
                f"{scene.path}: has no {SCENE_METADATA}; export {export} needs scenes made by `davis-ag generate` "
                "(the original download records no geometry, camera intrinsics or fruit registry)"
            )
    return scenes


def _texel_colours(files: list[str], texture: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """RGB of each textured triangle at its centroid's texture coordinate (repeating textures wrap)."""
    from davis_ag.render.textures import load_texture

    out = np.zeros((len(texture), 3), dtype=np.uint8)
    for index in np.unique(texture):
        image = load_texture(files[int(index)], "default")  # rows from v = 0, RGBA
        height, width = image.shape[:2]
        picked = np.flatnonzero(texture == index)
        u, v = uv[picked, 0] % 1.0, uv[picked, 1] % 1.0
        texels = image[np.minimum((v * height).astype(int), height - 1), np.minimum((u * width).astype(int), width - 1)]
        opaque = image[image[..., 3] >= 128][:, :3]
        mean = opaque.mean(axis=0) if len(opaque) else image[..., :3].reshape(-1, 3).mean(axis=0)
        out[picked] = np.where(texels[:, 3:4] >= 128, texels[:, :3], np.rint(mean).astype(np.uint8))
    return out


def face_colours(geometry: SceneGeometry) -> np.ndarray:
    """Each triangle's sRGB colour as uint8: its colour, or where a texture gives the colour its texel.

    Args:
        geometry: The scene's triangles.

    Returns:
        (n, 3) uint8.
    """
    rgb = np.rint(np.clip(geometry.colours[:, :3], 0.0, 1.0) * 255).astype(np.uint8)
    textured = (geometry.texture >= 0) & (geometry.mode == TEXTURE)
    if textured.any():
        centroid = geometry.uvs[textured].mean(axis=1)
        rgb[textured] = _texel_colours(geometry.texture_files, geometry.texture[textured], centroid)
    return rgb


def world_triangles(scene: Scene) -> WorldTriangles:
    """Reopen a scene's geometry with every triangle's labels.

    Args:
        scene: A scene of :func:`geometry_scenes`.

    Returns:
        The :class:`WorldTriangles`.

    Raises:
        UserError: when the scene cannot be reopened as it was drawn (:func:`davis_ag.live.reopen.regrow`).
    """
    assets = reopen_assets(read_settings(scene.path), labelled=True)
    assert assets.organ_of_uuid is not None and assets.plant_of_uuid is not None  # labelled=True
    geometry = assets.geometry
    uuids = geometry.uuids.astype(np.int64)
    fruit_of_uuid = np.full(assets.uuid_count, NONE, dtype=np.int32)
    for fruit_id, members in assets.fruit_uuids.items():
        fruit_of_uuid[np.asarray(members, dtype=np.int64)] = fruit_id
    return WorldTriangles(
        scene,
        geometry,
        assets.organ_of_uuid[uuids].astype(np.uint8),
        fruit_of_uuid[uuids],
        assets.plant_of_uuid[uuids].astype(np.int32),
        face_colours(geometry),
        ORGAN_NAMES,
    )


@dataclass(frozen=True)
class Part:
    """The triangles of one plant's organ, or of one fruit: a USD mesh prim, a GLB node.

    Attributes:
        group: ``plant_NNN`` (the plant's index) or ``environment`` (the soil and whatever is
            of no plant).
        name: The organ class's name, or ``fruit_<id>`` for a fruit body.
        organ: Organ class value.
        plant: Plant index, :data:`NONE` for none.
        fruit: Fruit id, :data:`NONE` for none.
        faces: Indices of its triangles.
    """

    group: str
    name: str
    organ: int
    plant: int
    fruit: int
    faces: np.ndarray


def identifier(text: str) -> str:
    """A name as USD and glTF take it: letters, digits and underscores, not starting with a digit."""
    cleaned = "".join(c if c.isascii() and (c.isalnum() or c == "_") else "_" for c in text)
    return cleaned if cleaned and not cleaned[0].isdigit() else f"_{cleaned}"


def parts(world: WorldTriangles) -> list[Part]:
    """The scene split by plant and organ, every fruit body its own part, in a stable order
    (the environment first, then plants by index; organs by class value, fruit by id)."""
    keys = np.stack([world.plant, world.organ.astype(np.int32), world.fruit], axis=1)
    unique, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    grouped = np.split(np.argsort(inverse.ravel(), kind="stable"), np.cumsum(counts)[:-1])
    out = []
    for (plant, organ, fruit), faces in zip(unique.tolist(), grouped):
        out.append(
            Part(
                f"plant_{plant:03d}" if plant != NONE else "environment",
                f"fruit_{fruit}" if fruit != NONE else identifier(world.class_name(organ)),
                organ,
                plant,
                fruit,
                faces,
            )
        )
    return out
