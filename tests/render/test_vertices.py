"""The vertex buffer: its layout agrees with what moderngl reads, Helios's draw order, the soil's texture."""

from __future__ import annotations

import re

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from davis_ag.render.scene_geometry import SceneGeometry
from davis_ag.render.vertices import SHADOW_FORMAT, VERTEX_DTYPE, VERTEX_FORMAT, interleaved_vertices


def offsets(layout: tuple[str, ...]) -> dict[str, tuple[int, int]]:
    """Each attribute of a moderngl buffer format (``"3f 12x 1i", "in_a", "in_b"``): its byte
    offset and size in one vertex, padding (``12x``) skipped; ``"_end"``: the vertex's size."""
    at, found, names = 0, {}, iter(layout[1:])
    for count, kind in re.findall(r"(\d+)([fuix])", layout[0]):
        size = int(count) * (1 if kind == "x" else 4)
        if kind != "x":
            found[next(names).removeprefix("in_")] = (at, size)
        at += size
    found["_end"] = (at, 0)
    return found


def test_both_formats_read_each_attribute_where_the_dtype_writes_it() -> None:
    fields = {name: (offset, dtype.itemsize) for name, (dtype, offset) in VERTEX_DTYPE.fields.items()}
    assert offsets(VERTEX_FORMAT) == {**fields, "_end": (VERTEX_DTYPE.itemsize, 0)}
    shadow = offsets(SHADOW_FORMAT)
    assert shadow.pop("_end") == (VERTEX_DTYPE.itemsize, 0)  # the same stride
    assert shadow == {name: fields[name] for name in ("position", "uv", "texture", "mode")}


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
