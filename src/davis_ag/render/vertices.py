"""The scene's one vertex buffer as our renderer draws it: every triangle's corners with their
texture coordinates, normal, linear albedo, primitive id, texture layer and shading mode.
"""

from __future__ import annotations

import numpy as np

from davis_ag.render.scene_geometry import SceneGeometry
from davis_ag.render.textures import decode_srgb

#: Helios's boost of vertex colours (its Visualizer's shader multiplies them by it).
COLOUR_BOOST = 1.5

#: Default look: one copy of a ground texture covers this many metres of soil. The Context's own
#: texture coordinates stretch one soil image over a whole 12 m tile (Helios shows its texels as
#: 2 cm blocks); the default look lays the image at this size instead, with mipmaps.
GROUND_REPEAT = 0.5
#: The scene's vertex buffer as moderngl reads it: the format, then the attribute names.
VERTEX_FORMAT = (
    "3f 2f 3f 4f 1u 1i 1i",
    "in_position",
    "in_uv",
    "in_normal",
    "in_colour",
    "in_id",
    "in_texture",
    "in_mode",
)
#: The same buffer as the shadow pass reads it: position, uv, texture and mode; the normal,
#: colour and id skipped (12, 16 and 4 bytes).
SHADOW_FORMAT = ("3f 2f 12x 16x 4x 1i 1i", "in_position", "in_uv", "in_texture", "in_mode")
#: One corner of the buffer, field by field in :data:`VERTEX_FORMAT`'s order.
VERTEX_DTYPE = np.dtype(
    [
        ("position", "f4", 3),
        ("uv", "f4", 2),
        ("normal", "f4", 3),
        ("colour", "f4", 4),
        ("id", "u4"),
        ("texture", "i4"),
        ("mode", "i4"),
    ]
)


def linear_albedo(colours: np.ndarray) -> np.ndarray:
    """Helios's vertex colours as its shader uses them: boosted, clipped, decoded to linear light."""
    out = np.array(colours, dtype=np.float64)
    out[:, :3] = decode_srgb(np.clip(out[:, :3] * COLOUR_BOOST, 0.0, 1.0))
    return out.astype(np.float32)


def interleaved_vertices(geometry: SceneGeometry, ground_repeat: float | None) -> tuple[np.ndarray, np.ndarray]:
    """The scene's triangles as one structured array of corners, in the order Helios draws them.

    Args:
        geometry: The scene's triangles.
        ground_repeat: Metres of soil one copy of its texture covers (the default look); None
            keeps the Context's own texture coordinates (the helios look).

    Returns:
        ``(vertex, order)``: three corners per triangle with the fields :data:`VERTEX_FORMAT`
        names, and the triangles' order (an index into ``geometry``'s arrays).
    """
    # Helios draws triangles, then patches, each in UUID order; later draws win depth ties
    # (GL_LEQUAL), so keep that order.
    order = np.lexsort((geometry.uuids, geometry.patch))
    vertex = np.zeros(geometry.triangle_count * 3, dtype=VERTEX_DTYPE)
    vertex["position"] = geometry.positions[order].reshape(-1, 3)
    uvs = geometry.uvs[order]
    if ground_repeat is not None:  # the soil's image laid at a fixed size, not stretched over the tile
        ground = ~geometry.caster[order] & (geometry.texture[order] >= 0)
        uvs = np.where(ground[:, None, None], geometry.positions[order][:, :, :2] / ground_repeat, uvs)
    vertex["uv"] = uvs.reshape(-1, 2)
    vertex["normal"] = geometry.normals[order].reshape(-1, 3)
    vertex["colour"] = np.repeat(linear_albedo(geometry.colours[order]), 3, axis=0)
    vertex["id"] = np.repeat(geometry.uuids[order].astype(np.uint64) + 1, 3).astype(np.uint32)
    vertex["texture"] = np.repeat(np.maximum(geometry.texture[order], 0), 3)
    vertex["mode"] = np.repeat(geometry.mode[order], 3)
    return vertex, order
