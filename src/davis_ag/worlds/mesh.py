"""``davis-ag export mesh``: each scene's triangles with their labels, as PLY or GLB (trimesh).

PLY (``OUT/<Group>/<NNN>.ply``, binary little-endian): one mesh, three vertices of its own per
triangle (``x y z``, float32 world metres, Z up), and per face ``red green blue alpha`` (its
colour, :func:`davis_ag.worlds.triangles.face_colours`), ``organ`` (uint8 organ class),
``fruit_id`` (the masks' type, :mod:`davis_ag.formats.masks`: uint8 with 255 for no fruit, or
uint16 with 65535 in a scene of more than 255 fruit) and ``plant`` (int16, -1 for none). The
class table is in the header's comments (``comment class 2 fruit``). plyfile, trimesh, Open3D,
MeshLab and CloudCompare read it.

GLB (``OUT/<Group>/<NNN>.glb``): one node per plant and organ class and one per fruit body (the
parts of :func:`davis_ag.worlds.triangles.parts`), named ``plant_000/leaf``,
``plant_000/fruit_7``, ``environment/soil``; each mesh's ``extras`` hold ``organ`` (name),
``organ_class``, ``plant`` and ``fruit_id`` (-1 for none), and the scene's ``extras`` the class
table. Colours are per vertex (each triangle's three the same). glTF is Y up: the nodes hang under
one root node ``davis_ag_world`` whose matrix turns the scene's Z-up metres into glTF's Y up, so
the vertices themselves are world coordinates.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from davis_ag.atomic_files import atomic_output
from davis_ag.data.reader import Scene
from davis_ag.formats.masks import mask_dtype, no_fruit_value
from davis_ag.worlds.triangles import NONE, WorldTriangles, parts, world_triangles

FORMATS = ("ply", "glb")
#: The GLB's root node, and its matrix: Z up (ours) to Y up (glTF's), x kept.
ROOT_NODE = "davis_ag_world"
Z_UP_TO_Y_UP = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]])


def _soup(world: WorldTriangles, faces: np.ndarray | None = None):
    """A trimesh of some triangles, each with three vertices of its own and its colour."""
    import trimesh

    faces = np.arange(world.count) if faces is None else faces
    vertices = world.geometry.positions[faces].reshape(-1, 3).astype(np.float64)
    colours = np.column_stack([world.rgb[faces], np.full(len(faces), 255, np.uint8)])
    return trimesh.Trimesh(
        vertices=vertices,
        faces=np.arange(len(vertices)).reshape(-1, 3),
        face_colors=colours,
        process=False,  # keep every triangle and its order: the labels are per face
    )


def ply_bytes(world: WorldTriangles) -> bytes:
    """The scene as one PLY with per-face ``organ``, ``fruit_id`` and ``plant``."""
    mesh = _soup(world)
    fruit_type = mask_dtype(len(world.scene.metadata.fruits) if world.scene.metadata else 0)
    no_fruit = no_fruit_value(fruit_type)
    mesh.face_attributes["organ"] = world.organ.astype(np.uint8)
    mesh.face_attributes["fruit_id"] = np.where(world.fruit == NONE, no_fruit, world.fruit).astype(fruit_type)
    mesh.face_attributes["plant"] = world.plant.astype(np.int16)
    data = mesh.export(file_type="ply", encoding="binary")
    # The class table as header comments, before the first element.
    comments = "".join(f"comment class {v} {name}\n" for v, name in enumerate(world.class_names)).encode()
    head, element, rest = data.partition(b"element ")
    return head + comments + element + rest


def glb_bytes(world: WorldTriangles) -> bytes:
    """The scene as a GLB, a node per plant and organ class and per fruit."""
    import trimesh

    scene = trimesh.Scene()
    scene.graph.update(frame_from=scene.graph.base_frame, frame_to=ROOT_NODE, matrix=Z_UP_TO_Y_UP)
    for part in parts(world):
        mesh = _soup(world, part.faces)
        mesh.metadata.update(
            organ=world.class_name(part.organ), organ_class=part.organ, plant=part.plant, fruit_id=part.fruit
        )
        name = f"{part.group}/{part.name}"
        scene.add_geometry(mesh, node_name=name, geom_name=name, parent_node_name=ROOT_NODE)
    scene.metadata["davis_ag"] = {"scene": world.scene.id, "classes": list(world.class_names), "units": "m"}
    return scene.export(file_type="glb")


def export_meshes(scenes: list[Scene], out: Path, fmt: str) -> dict[str, int]:
    """Write every scene's mesh under ``out`` (one already there, from a stopped export, is kept).

    Args:
        scenes: From :func:`davis_ag.worlds.triangles.geometry_scenes`.
        out: The claimed export folder.
        fmt: ``ply`` or ``glb``.

    Returns:
        Totals over the scenes written: ``scenes``, ``triangles``.
    """
    totals = {"scenes": 0, "triangles": 0}
    for scene in scenes:
        path = out / f"{scene.id}.{fmt}"
        if path.is_file():
            continue
        world = world_triangles(scene)
        data = ply_bytes(world) if fmt == "ply" else glb_bytes(world)
        with atomic_output(path) as handle:
            handle.write(data)
        totals["scenes"] += 1
        totals["triangles"] += world.count
    return totals
