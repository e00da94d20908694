"""Point clouds: depth pixels back to world points (the inverse of the camera's projection),
voxel thinning, and PLY files other libraries read."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from davis_ag.data.point_cloud import (
    POINT_DTYPE,
    POINT_DTYPE_16,
    Pinhole,
    read_ply,
    unproject,
    view_points,
    voxel_thin,
    widen,
    write_ply,
)
from davis_ag.scene.camera import Camera
from davis_ag.scene.view_grid import Viewpoint

poses = st.tuples(st.floats(-5, 5), st.floats(-5, 5), st.floats(0.1, 3), st.floats(-180, 180), st.floats(-80, 30))


@settings(max_examples=100, deadline=None)
@given(
    pose=poses,
    width=st.integers(16, 400),
    height=st.integers(16, 300),
    vfov=st.floats(20, 90),
    seed=st.integers(0, 2**31),
)
def test_unprojected_pixels_project_back_to_their_centres(pose, width, height, vfov, seed) -> None:
    camera = Camera(width, height, vfov)
    intrinsics = camera.intrinsics()
    pinhole = Pinhole(width, height, intrinsics["fx"], intrinsics["fy"], intrinsics["cx"], intrinsics["cy"])
    depth = np.random.default_rng(seed).uniform(0.05, 30.0, size=(height, width)).astype(np.float32)
    world = unproject(depth, pinhole, pose)
    view = Viewpoint(0, 0, 0, 0, 0, pose[:3], pose[:3], pose[3], pose[4])
    pixels, along = camera.project(view, world)
    rows, cols = np.indices((height, width))
    assert np.allclose(pixels[..., 0], cols + 0.5, atol=1e-6 * width)
    assert np.allclose(pixels[..., 1], rows + 0.5, atol=1e-6 * height)
    assert np.allclose(along, depth, rtol=1e-9, atol=1e-9)


def points_at(xyz: np.ndarray) -> np.ndarray:
    points = np.zeros(len(xyz), dtype=POINT_DTYPE)
    points["x"], points["y"], points["z"] = xyz.T
    points["organ"] = np.arange(len(xyz)) % 6
    points["fruit_id"] = np.arange(len(xyz)) % 256
    return points


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**31), n=st.integers(1, 400), voxel=st.floats(0.01, 1.0))
def test_voxel_thinning_keeps_the_first_point_of_every_occupied_voxel(seed: int, n: int, voxel: float) -> None:
    xyz = np.random.default_rng(seed).uniform(-2, 2, size=(n, 3)).astype(np.float32)
    points = points_at(xyz)
    kept = voxel_thin(points, voxel)

    def cells(p: np.ndarray) -> list[tuple]:
        return [tuple(c) for c in np.floor(np.stack([p["x"], p["y"], p["z"]], 1) / voxel).astype(np.int64)]

    first: dict[tuple, int] = {}
    for index, cell in enumerate(cells(points)):
        first.setdefault(cell, index)
    assert cells(kept) == [cells(points)[i] for i in sorted(first.values())]
    assert np.array_equal(kept, points[sorted(first.values())])  # whole points: labels never mixed
    assert voxel_thin(points, 0.0) is points


def test_ply_round_trips_and_other_libraries_read_it(tmp_path: Path) -> None:
    points = points_at(np.random.default_rng(1).uniform(-1, 1, size=(500, 3)).astype(np.float32))
    points["red"], points["view"] = 200, 7
    path = write_ply(points, tmp_path / "cloud" / "a.ply", "test")
    assert np.array_equal(read_ply(path), points)
    assert not list(path.parent.glob(".*.tmp"))
    trimesh = pytest.importorskip("trimesh")
    cloud = trimesh.load(path)
    assert isinstance(cloud, trimesh.PointCloud) and np.allclose(
        cloud.vertices, np.stack([points["x"], points["y"], points["z"]], 1), atol=1e-6
    )


def test_fruit_ids_widen_to_16_bits_only_for_a_scene_with_16_bit_masks(tmp_path: Path) -> None:
    points = points_at(np.random.default_rng(2).uniform(-1, 1, size=(50, 3)).astype(np.float32))
    points["fruit_id"][:5] = 255  # none
    path = write_ply(points, tmp_path / "narrow.ply")
    assert read_ply(path).dtype == POINT_DTYPE and b"fruit_id 255: none" in path.read_bytes()[:600]
    wide = widen(points)
    assert wide.dtype == POINT_DTYPE_16 and (wide["fruit_id"][:5] == 65535).all()
    assert np.array_equal(wide["fruit_id"][5:], points["fruit_id"][5:])
    wide["fruit_id"][5] = 300
    path = write_ply(wide, tmp_path / "wide.ply")
    back = read_ply(path)
    assert back.dtype == POINT_DTYPE_16 and np.array_equal(back, wide)
    assert b"property ushort fruit_id" in path.read_bytes()[:600] and b"fruit_id 65535: none" in path.read_bytes()[:600]


class _View:
    """What view_points reads of a view: one fruit with id 300 in a 16-bit mask."""

    name = "0003.jpeg"
    pose = (0.0, 0.0, 1.0, 0.0, 0.0)
    depth_path = Path("0003_depth.png")

    def depth(self) -> np.ndarray:
        return np.full((4, 6), 2.0, dtype=np.float32)

    def image(self) -> np.ndarray:
        return np.zeros((4, 6, 3), dtype=np.uint8)

    def classes(self) -> None:
        return None

    def mask(self) -> np.ndarray:
        mask = np.full((4, 6), 65535, dtype=np.uint16)
        mask[1:3, 2:4] = 300
        return mask


def test_view_points_keep_a_16_bit_fruit_id() -> None:
    points = view_points(_View(), Pinhole(6, 4, 3.0, 3.0, 3.0, 2.0))  # type: ignore[arg-type]
    assert points.dtype == POINT_DTYPE_16 and len(points) == 24
    assert sorted(set(points["fruit_id"].tolist())) == [300, 65535] and (points["fruit_id"] == 300).sum() == 4
    assert (points["view"] == 3).all()
