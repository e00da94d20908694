"""A Helios scene read out of its Context in bulk, as flat numpy arrays ready for a vertex buffer.

Every primitive becomes triangles (a patch, whose four corners Helios draws as a triangle fan,
becomes the two triangles (0, 1, 2) and (0, 2, 3)); each triangle vertex carries its position,
texture coordinate and normal, and each triangle its primitive's UUID, colour and texture. The
Context is read with its batch calls (one call per quantity for all primitives) and one call per
compound object for the object map and smooth normals; there is no Python loop over primitives.

Normals follow Helios's Visualizer: a triangle of an object whose surface normal is known
analytically (tubes, cones, spheres) or a polymesh that carries vertex normals is shaded with
per-vertex normals; every other primitive with its face normal.
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: Helios primitive types (``helios::PrimitiveType``).
PATCH, TRIANGLE = 0, 1
#: Helios object type of a polymesh.
POLYMESH = 5

#: Texture modes per triangle: plain colour, texture colour (alpha-masked), colour masked by the
#: texture's alpha (a texture colour override).
COLOUR, TEXTURE, COLOUR_MASKED = 0, 1, 2


@dataclass
class SceneGeometry:
    """Triangles of a scene, three vertices each, in world metres.

    Attributes:
        positions: (n, 3, 3) float32 vertex positions.
        uvs: (n, 3, 2) float32 texture coordinates (0 where untextured).
        normals: (n, 3, 3) float32 vertex normals (the face normal where not smooth).
        uuids: (n,) uint32 Helios UUID of each triangle's primitive.
        colours: (n, 4) float32 RGBA colour of the primitive.
        texture: (n,) int32 index into ``texture_files``, -1 for none.
        mode: (n,) int32 :data:`COLOUR`, :data:`TEXTURE` or :data:`COLOUR_MASKED`.
        caster: (n,) bool, whether the triangle casts shadows (not the soil).
        patch: (n,) bool, whether the triangle is half of a patch (Helios draws patches last).
        texture_files: The texture images, by index.
    """

    positions: np.ndarray
    uvs: np.ndarray
    normals: np.ndarray
    uuids: np.ndarray
    colours: np.ndarray
    texture: np.ndarray
    mode: np.ndarray
    caster: np.ndarray
    patch: np.ndarray
    texture_files: list[str] = field(default_factory=list)

    @property
    def triangle_count(self) -> int:
        """How many triangles."""
        return len(self.uuids)

    def caster_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper corners of the shadow casters' bounding box (all geometry if none)."""
        points = self.positions[self.caster] if self.caster.any() else self.positions
        points = points.reshape(-1, 3)
        return points.min(axis=0), points.max(axis=0)

    def save(self, path: Path) -> None:
        """Write to an ``.npz`` file (for tools and tests that draw without growing a scene)."""
        np.savez_compressed(
            path,
            positions=self.positions,
            uvs=self.uvs,
            normals=self.normals,
            uuids=self.uuids,
            colours=self.colours,
            texture=self.texture,
            mode=self.mode,
            caster=self.caster,
            patch=self.patch,
            texture_files=np.array(self.texture_files, dtype=object),
        )

    @classmethod
    def load(cls, path: Path) -> SceneGeometry:
        """Read what :meth:`save` wrote."""
        with np.load(path, allow_pickle=True) as data:
            fields = {k: data[k] for k in data.files if k != "texture_files"}
            return cls(**fields, texture_files=[str(f) for f in data["texture_files"]])


def _flat(values: tuple[np.ndarray, np.ndarray], width: int) -> tuple[np.ndarray, np.ndarray]:
    """A batch call's (flat data, offsets in floats) as rows of ``width`` and a count per primitive."""
    data, offsets = values
    counts = np.diff(np.asarray(offsets, dtype=np.int64)) // width
    return np.asarray(data, dtype=np.float32).reshape(-1, width), counts


def _fan_triangles(counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertex indices of each primitive's triangles (fan from its first vertex) and their primitive.

    Args:
        counts: Vertices per primitive (3 for a triangle, 4 for a patch).

    Returns:
        (m, 3) indices into the concatenated vertex rows and (m,) primitive index per triangle.
    """
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    per = np.maximum(counts - 2, 0)
    primitive = np.repeat(np.arange(len(counts)), per)
    k = np.arange(len(primitive)) - np.repeat(np.cumsum(per) - per, per)  # triangle index within primitive
    base = first[primitive]
    return np.stack([base, base + k + 1, base + k + 2], axis=1), primitive


def _smooth_normals(context, object_ids: list[int], object_uuids: list[np.ndarray]) -> dict[int, np.ndarray]:
    """Per-vertex normals of triangles Helios shades smoothly, by UUID: (3, 3) each."""
    from pyhelios.plugins import helios_lib
    from pyhelios.wrappers import UContextWrapper

    normals: dict[int, np.ndarray] = {}
    raw = context.getNativePtr()
    for object_id, uuids in zip(object_ids, object_uuids):
        if not len(uuids):
            continue
        kind = context.getObjectType(object_id)
        smooth = context.doesObjectHaveAnalyticVertexNormals(object_id)
        if kind == POLYMESH and not smooth:
            smooth = int(context.getPolymeshObjectVertexNormalSource(object_id)) != 0
        if not smooth:
            continue
        if kind == POLYMESH:  # a polymesh's normals per face corner, from its shared vertices
            vertex_normals = np.asarray(
                [[v.x, v.y, v.z] for v in context.getPolymeshObjectVertexNormals(object_id)], dtype=np.float32
            )
            faces = np.asarray([[f.x, f.y, f.z] for f in context.getPolymeshObjectFaces(object_id)], dtype=np.int64)
            face_index = np.asarray([context.getPolymeshObjectFaceIndexForPrimitive(object_id, int(u)) for u in uuids])
            for uuid, face in zip(uuids, faces[face_index]):
                normals[int(uuid)] = vertex_normals[face]
            continue
        UContextWrapper._require_ctx_scalar_api()
        array = (ctypes.c_uint * len(uuids))(*[int(u) for u in uuids])
        counts_ptr = ctypes.POINTER(ctypes.c_uint)()
        size = ctypes.c_uint()
        pointer = helios_lib.getObjectPrimitiveVertexNormalsBatch(
            raw, int(object_id), array, len(uuids), ctypes.byref(counts_ptr), ctypes.byref(size)
        )
        if not size.value:
            continue
        values = np.ctypeslib.as_array(pointer, shape=(size.value,)).astype(np.float32).reshape(-1, 3)
        counts = np.ctypeslib.as_array(counts_ptr, shape=(len(uuids),)).astype(np.int64)
        starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        for uuid, start, count in zip(uuids, starts, counts):
            if count == 3:
                normals[int(uuid)] = values[start : start + 3]
    return normals


#: A primitive whose every vertex lies this close to the ground plane (z = 0) is soil: it
#: receives shadows but casts none (it could only shade the ground it lies on).
GROUND_TOLERANCE = 1e-3


def read_scene_geometry(context) -> SceneGeometry:
    """Read every visible patch and triangle of a Helios Context.

    Args:
        context: The pyhelios Context.

    Returns:
        The :class:`SceneGeometry`.
    """
    uuid_list = [int(u) for u in context.getAllUUIDs()]
    uuids = np.asarray(uuid_list, dtype=np.uint32)
    types = np.asarray(context.getPrimitiveType(uuid_list), dtype=np.int64)
    vertices, counts = _flat(context.getPrimitiveVertices(uuid_list), 3)
    uv_rows, uv_counts = _flat(context.getPrimitiveTextureUV(uuid_list), 2)
    colours = np.asarray(context.getPrimitiveColor(uuid_list), dtype=np.float32).reshape(-1, 3)
    face_normals = np.asarray(context.getPrimitiveNormal(uuid_list), dtype=np.float32).reshape(-1, 3)
    files = context.getPrimitiveTextureFile(uuid_list)

    keep = np.isin(types, (PATCH, TRIANGLE)) & np.isin(counts, (3, 4))
    # Untextured primitives carry no UVs: give every vertex a (0, 0) row so rows line up.
    uv_full = np.zeros((len(vertices), 2), dtype=np.float32)
    has_uv = uv_counts == counts
    vertex_primitive = np.repeat(np.arange(len(counts)), counts)
    uv_primitive = np.repeat(np.arange(len(uv_counts)), uv_counts)
    uv_full[has_uv[vertex_primitive]] = uv_rows[has_uv[uv_primitive]]

    index, primitive = _fan_triangles(np.where(keep, counts, 0))
    positions = vertices[index]
    uvs = uv_full[index]
    normals = np.repeat(face_normals[primitive][:, None, :], 3, axis=1)

    # Textures: one index per distinct file; a texture colour override keeps the colour and uses
    # the texture's alpha only (checked per compound object, whose primitives share it).
    names = sorted({f for f in files if f})
    texture_of = {name: i for i, name in enumerate(names)}
    primitive_texture = np.asarray([texture_of.get(f, -1) for f in files], dtype=np.int32)
    mode = np.where(primitive_texture >= 0, TEXTURE, COLOUR).astype(np.int32)

    object_ids = [int(o) for o in context.getAllObjectIDs()]
    object_uuids = [np.asarray(context.getObjectPrimitiveUUIDs(o), dtype=np.int64) for o in object_ids]
    position_of = np.full(int(uuids.max()) + 1 if len(uuids) else 1, -1, dtype=np.int64)
    position_of[uuids] = np.arange(len(uuids))
    for object_id, members in zip(object_ids, object_uuids):
        if (
            len(members)
            and primitive_texture[position_of[members[0]]] >= 0
            and context.isPrimitiveTextureColorOverridden(int(members[0]))
        ):
            mode[position_of[members]] = COLOUR_MASKED
    smooth = _smooth_normals(context, object_ids, object_uuids)
    if smooth:
        smooth_uuids = np.fromiter(smooth.keys(), dtype=np.int64)
        smooth_values = np.stack(list(smooth.values())).astype(np.float32)
        rows = position_of[smooth_uuids]
        triangle_rows = np.full(len(uuids), -1, dtype=np.int64)
        triangle_rows[rows] = np.arange(len(rows))
        lookup = triangle_rows[primitive]
        chosen = (lookup >= 0) & (counts[primitive] == 3)
        normals[chosen] = smooth_values[lookup[chosen]]

    caster = np.abs(positions[:, :, 2]).max(axis=1) > GROUND_TOLERANCE
    return SceneGeometry(
        positions=np.ascontiguousarray(positions, dtype=np.float32),
        uvs=np.ascontiguousarray(uvs, dtype=np.float32),
        normals=np.ascontiguousarray(normals, dtype=np.float32),
        uuids=uuids[primitive],
        colours=np.concatenate([colours[primitive], np.ones((len(primitive), 1), np.float32)], axis=1),
        texture=primitive_texture[primitive],
        mode=mode[primitive],
        caster=caster,
        patch=types[primitive] == PATCH,
        texture_files=names,
    )
