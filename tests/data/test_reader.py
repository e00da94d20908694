"""The reader on our tiny datasets, on original-download variations, and its pure parsers."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from davis_ag.data.reader import (
    Box,
    NotFoundError,
    boxes_from_mask,
    exposure_rate,
    normalise_view_name,
    open_dataset,
    parse_box,
    parse_pose,
)
from davis_ag.errors import UserError
from davis_ag.formats.models import SplitsFile
from davis_ag.scene.specs import INVERSE_ACTION, MP_ACTIONS, SP_ACTIONS
from layout_factory import write_original_style_dataset, write_tiny_dataset
from wide_masks import widen_scene


@pytest.fixture(scope="module")
def ours(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("ours")
    write_tiny_dataset(root, "sp", "strawberry", scenes=2)
    write_tiny_dataset(root, "mp", "vine", scenes=1)
    return root


@pytest.fixture(scope="module")
def original(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_original_style_dataset(tmp_path_factory.mktemp("orig"), "mp", "tomato", missing_mask=True)


def test_open_root_group_and_scene_folder(ours: Path) -> None:
    ds = open_dataset(ours)
    assert ds.root == ours.absolute()
    assert [s.id for s in ds.scenes] == ["Multi-Vine/000", "Single-Strawberry/000", "Single-Strawberry/001"]
    assert len(ds) == 3 and [s.id for s in ds] == [s.id for s in ds.scenes]
    group = open_dataset(ours / "Single-Strawberry")
    assert group.root == ours.absolute() and [s.id for s in group] == ["Single-Strawberry/000", "Single-Strawberry/001"]
    single = open_dataset(ours / "Single-Strawberry" / "001")
    assert [s.id for s in single] == ["Single-Strawberry/001"]
    assert single.splits == ds.splits
    # A path through `..` names the folder it reaches: `001/..` is the group, not a scene `../001`.
    through = open_dataset(ours / "Single-Strawberry" / "001" / "..")
    assert through.root == ours.absolute() and [s.id for s in through] == [s.id for s in group]


def test_scene_properties(ours: Path) -> None:
    ds = open_dataset(ours)
    sp, mp = ds.scene("Single-Strawberry/000"), ds.scene("Multi-Vine/000")
    assert (sp.scenario, sp.crop, sp.group) == ("sp", "strawberry", "Single-Strawberry")
    assert (mp.scenario, mp.crop) == ("mp", "vine")
    assert sp.actions == SP_ACTIONS and mp.actions == MP_ACTIONS
    names = list(sp.views)
    assert names[0] == "0001.jpeg" and names == sorted(names) and len(sp) == len(names)
    assert sp.view("0001") is sp.view("0001.jpeg") is sp.view(1)
    # A scene is the sequence of its views: by position from 0 (view(1) is the first), slices, len.
    assert isinstance(sp, Sequence) and sp[0] is sp.view(1) and sp[-1].name == names[-1]
    assert [v.name for v in sp[1:3]] == names[1:3] and list(sp) == list(sp.views.values())
    assert sp.index(sp[2]) == 2 and sp[2] in sp
    with pytest.raises(IndexError, match=f"has {len(sp)} views"):
        sp[len(sp)]
    assert sp.metadata is not None and sp.metadata.camera.width == 128
    assert set(sp.metadata.visible_fraction) == set(names)
    assert ds.splits == SplitsFile(
        seed=0, train=["Single-Strawberry/000", "Multi-Vine/000"], test=["Single-Strawberry/001"]
    )
    assert ds.splits.train == ["Single-Strawberry/000", "Multi-Vine/000"]


def test_lookup_errors_are_user_and_key_errors(ours: Path) -> None:
    ds = open_dataset(ours)
    with pytest.raises(NotFoundError, match="no scene 'Single-Tomato/000'") as caught:
        ds.scene("Single-Tomato/000")
    assert isinstance(caught.value, UserError) and isinstance(caught.value, KeyError)
    assert "'" not in str(caught.value)[:1]
    with pytest.raises(KeyError, match=r"has no view '9999'"):
        ds.scenes[0].view("9999")
    with pytest.raises(UserError, match="unknown action 'jump'"):
        ds.scenes[0].view(1).next("jump")


def test_pointers_are_consistent_and_invertible(ours: Path) -> None:
    for scene in open_dataset(ours):
        invalid = 0
        for view in scene:
            assert set(view.pointers) == set(scene.actions)
            for action in scene.actions:
                target = view.next(action)
                if target is None:
                    invalid += 1
                    assert view.pointers[action] == ""
                else:
                    assert target.scene is scene and target.name == view.pointers[action]
                    assert target.next(INVERSE_ACTION[action]) is view
        assert invalid > 0


def test_pixels_and_boxes_follow_writer_conventions(ours: Path) -> None:
    scene = open_dataset(ours).scene("Single-Strawberry/000")
    for view in list(scene)[:10]:
        image, mask = view.image(), view.mask()
        assert image.shape == (72, 128, 3) and image.dtype == np.uint8
        assert mask is not None and mask.shape == (72, 128) and mask.dtype == np.uint8
        assert boxes_from_mask(mask) == {b.fruit_id: b for b in view.boxes}
        assert view.pose is not None and len(view.pose) == 5
        assert view.image_path.name == view.name and view.mask_path.name == view.name[:4] + "_seg.png"
        for box in view.boxes:
            assert view.box(box.fruit_id) is box
            assert 0 < exposure_rate(mask, box) <= 1
    assert scene.view(1).box(254) is None


def test_a_16_bit_mask_reads_with_its_ids_above_255(tmp_path: Path) -> None:
    root = write_tiny_dataset(tmp_path, "sp", "strawberry", scenes=1)
    widen_scene(root / "Single-Strawberry" / "000")
    scene = open_dataset(root).scene("Single-Strawberry/000")
    seen = 0
    for view in scene:
        mask = view.mask()
        assert mask is not None and mask.dtype == np.uint16 and mask.shape == (72, 128)
        assert boxes_from_mask(mask) == {b.fruit_id: b for b in view.boxes}
        for box in view.boxes:
            assert box.fruit_id >= 300 and 0 < exposure_rate(mask, box) <= 1
            seen += 1
    assert seen > 10


def test_oer_varies_and_fruits_hide(ours: Path) -> None:
    # The factory's occluders must make the benchmark non-trivial: a fruit's OER changes with
    # the view and some fruit vanish from some views.
    scene = open_dataset(ours).scene("Single-Strawberry/000")
    oer: dict[int, list[float]] = {}
    for view in scene:
        mask = view.mask()
        for box in view.boxes:
            oer.setdefault(box.fruit_id, []).append(exposure_rate(mask, box))
    assert max(max(v) - min(v) for v in oer.values()) > 0.3
    assert any(len(v) < len(scene) for v in oer.values())


def test_original_download_variations(ours: Path, original: Path) -> None:
    scene = open_dataset(original).scenes[0]
    assert scene.id == "Multi-Tomato/000" and scene.metadata is None
    assert open_dataset(original).splits is None
    first = scene.view("0001.jpeg")
    assert first.pose is None and first.mask() is None
    assert scene.view(2).pose is not None and scene.view(2).mask() is not None
    assert all(isinstance(v, int) for b in first.boxes for v in (b.xmin, b.width, b.fruit_id))
    assert scene.actions == MP_ACTIONS
    # Dropped "" pointers read as invalid moves; stripped suffixes resolve.
    assert first.pointers["backward"] == "" and first.next("backward") is None
    assert scene.view(2).next("forward") is not None
    raw = json.loads(scene.annotations_path.read_text())
    assert "0001" in raw and "backward" not in raw["0001"] and "capture_time" in raw["0001"]


def test_original_matches_ours_for_same_seed(tmp_path: Path, original: Path) -> None:
    write_tiny_dataset(tmp_path, "mp", "tomato", scenes=1)
    ours, theirs = open_dataset(tmp_path).scenes[0], open_dataset(original).scenes[0]
    assert list(ours.views) == list(theirs.views)
    for a, b in zip(ours, theirs):
        assert a.boxes == b.boxes and a.pointers == b.pointers


def test_not_a_dataset(tmp_path: Path) -> None:
    with pytest.raises(UserError, match="not a DAVIS-Ag dataset"):
        open_dataset(tmp_path)
    with pytest.raises(UserError, match="no such folder"):
        open_dataset(tmp_path / "nope")
    (tmp_path / "file.txt").write_text("x")
    with pytest.raises(UserError, match="is a file"):
        open_dataset(tmp_path / "file.txt")


def test_malformed_annotations_raise_user_error(tmp_path: Path) -> None:
    scene_dir = tmp_path / "Odd-Group" / "000"
    scene_dir.mkdir(parents=True)
    (scene_dir / "annotations.json").write_text('{"0001.jpeg": {"bounding_boxes": [[1, 2]]}}')
    scene = open_dataset(tmp_path).scenes[0]
    assert scene.scenario is None and scene.crop is None
    with pytest.raises(UserError, match=r"annotations.json: entry '0001.jpeg': a box must be"):
        _ = scene.views
    (scene_dir / "annotations.json").write_text('{"0001.jpeg": ')
    with pytest.raises(UserError, match="not valid JSON"):
        _ = open_dataset(tmp_path).scenes[0].views
    (scene_dir / "annotations.json").write_text('{"0001": {"forward": "0002"}}')
    scene = open_dataset(scene_dir).scenes[0]
    assert scene.actions == ("forward",)
    with pytest.raises(UserError, match=r"forward points to 0002.jpeg"):
        scene.view(1).next("forward")
    with pytest.raises(UserError, match="image file missing"):
        scene.view(1).image()


# --- pure parsers -------------------------------------------------------------------------------

stems = st.from_regex(r"[0-9A-Za-z_-]{1,8}", fullmatch=True)


@given(stems)
def test_view_name_normalisation(stem: str) -> None:
    name = normalise_view_name(stem)
    assert name == f"{stem}.jpeg"
    assert normalise_view_name(name) == name == normalise_view_name(f"{stem}.JPG")


@given(st.integers(1, 9999))
def test_view_numbers(n: int) -> None:
    assert normalise_view_name(n) == normalise_view_name(f"{n:04d}") == f"{n:04d}.jpeg"


@pytest.mark.parametrize("bad", ["a/b.jpeg", "x.png", ".jpeg", 0, 1.5, None])
def test_bad_view_names(bad: object) -> None:
    with pytest.raises(ValueError):
        normalise_view_name(bad)  # type: ignore[arg-type]


boxes = st.builds(
    Box, st.integers(0, 2000), st.integers(0, 2000), st.integers(1, 500), st.integers(1, 500), st.integers(0, 254)
)


@given(boxes, st.booleans())
def test_box_round_trip(box: Box, as_float: bool) -> None:
    raw = [float(v) for v in box.to_list()] if as_float else box.to_list()
    assert parse_box(raw) == box
    assert box.xmax - box.xmin + 1 == box.width and box.area == box.width * box.height


@pytest.mark.parametrize(
    "bad", [[1, 2, 3, 4], "1,2,3,4,5", [1, 2, 3, 4, "a"], [1, 2, 3, 4, True], [1, 2, float("nan"), 4, 5]]
)
def test_bad_boxes(bad: object) -> None:
    with pytest.raises(ValueError):
        parse_box(bad)


@given(st.lists(st.floats(-100, 100), min_size=3, max_size=6))
def test_pose_round_trip(values: list[float]) -> None:
    assert parse_pose(values) == tuple(values)
    assert parse_pose(None) is None


small_boxes = st.builds(
    Box, st.integers(0, 40), st.integers(0, 30), st.integers(1, 24), st.integers(1, 18), st.integers(0, 254)
)


@given(small_boxes, st.integers(0, 254))
def test_exposure_rate_and_mask_boxes(box: Box, other: int) -> None:
    mask = np.full((48, 64), 255, dtype=np.uint8)
    mask[box.ymin : box.ymax + 1, box.xmin : box.xmax + 1] = box.fruit_id
    assert exposure_rate(mask, box) == 1.0
    assert boxes_from_mask(mask) == {box.fruit_id: box}
    # Cover the top row with another fruit: OER drops by exactly that row.
    if other != box.fruit_id:
        mask[box.ymin, box.xmin : box.xmax + 1] = other
        assert exposure_rate(mask, box) == pytest.approx((box.height - 1) / box.height)


def test_exposure_rate_edges() -> None:
    mask = np.full((10, 10), 255, dtype=np.uint8)
    mask[0:2, 0:2] = 3
    assert exposure_rate(mask, Box(-2, -2, 4, 4, 3)) == 4 / 16
    assert exposure_rate(mask, Box(0, 0, 0, 4, 3)) == 0.0
    assert exposure_rate(mask, Box(0, 0, 4, 4, 7)) == 0.0
    assert boxes_from_mask(np.full((4, 4), 255, dtype=np.uint8)) == {}
