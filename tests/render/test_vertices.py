"""The vertex buffer: its layout agrees with what moderngl reads, Helios's draw order, the soil's texture."""

from __future__ import annotations

import re

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from davis_ag.render.scene_geometry import SceneGeometry
from davis_ag.render.vertices import SHADOW_FORMAT, VERTEX_DTYPE, VERTEX_FORMAT, interleaved_vertices

SIZES = {"f": 4, "u": 4, "i": 4}


def format_bytes(layout: str) -> int:
    """Bytes one vertex of a moderngl buffer format takes (``3f``: 12, ``12x``: 12)."""
    total = 0
    for count, kind in re.findall(r"(\d+)([fuix])", layout):
        total += int(count) * (1 if kind == "x" else SIZES[kind])
    return total


def test_both_formats_read_the_buffer_the_dtype_writes() -> None:
    assert format_bytes(VERTEX_FORMAT[0]) == VERTEX_DTYPE.itemsize
    assert format_bytes(SHADOW_FORMAT[0]) == VERTEX_DTYPE.itemsize
    assert len(VERTEX_FORMAT) - 1 == len(VERTEX_DTYPE.names)


def geometry(uuids: list[int], patch: list[bool], ground: int) -> SceneGeometry:
    n = len(uuids)
    positions = np.arange(n * 9, dtype=np.float32).reshape(n, 3, 3)
    texture = np.zeros(n, np.int32)
    caster = np.arange(n) >= ground  # the first `ground` triangles are soil
    return SceneGeometry(
        positions=positions,
        uvs=np.full((n, 3, 2), 0.25, np.float32),
        normals=np.zeros((n, 3, 3), np.float32),
        uuids=np.array(uuids, np.uint32),
        colours=np.full((n, 4), 0.5, np.float32),
        texture=texture,
        mode=np.zeros(n, np.int32),
        caster=caster,
        patch=np.array(patch, bool),
    )


@given(st.lists(st.tuples(st.integers(0, 10_000), st.booleans()), min_size=1, max_size=30, unique_by=lambda t: t[0]))
def test_triangles_come_in_helios_draw_order(triangles: list[tuple[int, bool]]) -> None:
    # Helios draws triangles, then patches, each in UUID order; ids are the UUID + 1 (0: no primitive).
    uuids, patch = [t[0] for t in triangles], [t[1] for t in triangles]
    vertex, order = interleaved_vertices(geometry(uuids, patch, 0), ground_repeat=None)
    drawn = vertex["id"][::3] - 1
    assert sorted(drawn.tolist(), key=lambda u: (patch[uuids.index(u)], u)) == drawn.tolist()
    assert (vertex["id"][0::3] == vertex["id"][2::3]).all() and list(np.array(uuids)[order]) == drawn.tolist()


def test_the_default_look_lays_the_soil_texture_by_position() -> None:
    scene = geometry([1, 2], [False, False], ground=1)
    helios, _ = interleaved_vertices(scene, ground_repeat=None)
    assert (helios["uv"] == 0.25).all()  # the Context's own coordinates
    default, _ = interleaved_vertices(scene, ground_repeat=0.5)
    assert np.allclose(default["uv"][:3], scene.positions[0, :, :2] / 0.5)  # soil: metres / repeat
    assert (default["uv"][3:] == 0.25).all()  # plants keep theirs
