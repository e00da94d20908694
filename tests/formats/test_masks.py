"""The instance masks' rule: uint8 (255 = no fruit) up to 255 fruit, uint16 (65535) above; and the
writer's PNG encoding read back by the reader and the validator with every id and no-fruit kept."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from PIL import Image

from davis_ag.data.pixel_checks import read_mask
from davis_ag.data.safe_read import load_pixels
from davis_ag.formats.layout import view_file_name, write_view_files
from davis_ag.formats.masks import (
    MAX_FRUIT,
    MAX_FRUIT_ID,
    NO_FRUIT_8,
    NO_FRUIT_16,
    as_mask,
    empty_mask,
    fruit_pixels,
    mask_dtype,
    mask_from_image,
    mask_image,
    max_fruit_id,
    no_fruit_value,
    segmentation_convention,
)
from davis_ag.formats.models import MAX_FRUIT_ID as MODEL_MAX_FRUIT_ID
from davis_ag.scene.specs import MAX_FRUIT as SPEC_MAX_FRUIT
from davis_ag.scene.specs import NO_FRUIT


@pytest.mark.parametrize(
    ("count", "dtype"), [(0, np.uint8), (1, np.uint8), (255, np.uint8), (256, np.uint16), (65535, np.uint16)]
)
def test_the_fruit_count_picks_the_mask_type(count: int, dtype: type) -> None:
    assert mask_dtype(count) == np.dtype(dtype)


@pytest.mark.parametrize("count", [-1, 65536, 10**6])
def test_no_mask_holds_a_negative_count_or_more_than_65535_fruit(count: int) -> None:
    with pytest.raises(ValueError, match=r"0..65535"):
        mask_dtype(count)


def test_no_fruit_is_the_largest_value_of_the_type() -> None:
    assert no_fruit_value(np.uint8) == NO_FRUIT_8 == NO_FRUIT == 255
    assert no_fruit_value(np.dtype(np.uint16)) == NO_FRUIT_16 == 65535
    assert no_fruit_value(np.zeros((2, 2), np.uint16)) == 65535
    assert (max_fruit_id(np.uint8), max_fruit_id(np.uint16)) == (254, 65534)
    assert MAX_FRUIT == SPEC_MAX_FRUIT == 65535 and MAX_FRUIT_ID == MODEL_MAX_FRUIT_ID == 65534
    for bad in (np.int32, np.uint32, np.float32, np.zeros(3, bool)):
        with pytest.raises(ValueError, match="uint8 or uint16"):
            no_fruit_value(bad)


def test_empty_masks_and_fruit_pixels() -> None:
    narrow, wide = empty_mask((3, 4), 10), empty_mask((3, 4), 300)
    assert narrow.dtype == np.uint8 and (narrow == 255).all() and not fruit_pixels(narrow).any()
    assert wide.dtype == np.uint16 and (wide == 65535).all() and not fruit_pixels(wide).any()
    wide[1, 2], wide[0, 0] = 300, 255  # 255 is a fruit id in a 16-bit mask
    assert fruit_pixels(wide).tolist() == [[True, False, False, False], [False, False, True, False], [False] * 4]


def test_the_convention_text_of_a_paper_scene_is_unchanged() -> None:
    old = "uint8 fruit_id per pixel for fruit with a box in the view, 255 elsewhere"
    assert segmentation_convention(0) == segmentation_convention(255) == old
    assert segmentation_convention(256) == "uint16 fruit_id per pixel for fruit with a box in the view, 65535 elsewhere"


def test_an_8_bit_mask_is_encoded_byte_for_byte_as_before(tmp_path: Path) -> None:
    mask = np.random.default_rng(0).integers(0, 256, size=(37, 53), dtype=np.uint8)
    write_view_files(tmp_path, "0001.jpeg", segmentation=mask)
    before = io.BytesIO()
    Image.fromarray(mask, mode="L").save(before, format="PNG", compress_level=1)  # the encoding of old
    assert (tmp_path / "0001_seg.png").read_bytes() == before.getvalue()
    with Image.open(tmp_path / "0001_seg.png") as im:
        assert im.mode == "L"


def test_a_16_bit_mask_is_a_16_bit_greyscale_png(tmp_path: Path) -> None:
    mask = np.array([[0, 300], [65534, 65535]], dtype=np.uint16)
    write_view_files(tmp_path, "0001.jpeg", segmentation=mask)
    with Image.open(tmp_path / "0001_seg.png") as im:
        assert im.mode == "I;16" and im.format == "PNG"
    for bad in (mask.astype(np.int32), np.zeros((2, 2, 3), np.uint8)):
        with pytest.raises(ValueError):
            mask_image(bad)


@st.composite
def masks(draw: st.DrawFn) -> np.ndarray:
    """A mask of either type: fruit ids of the type's range, no fruit sprinkled in."""
    dtype = np.dtype(draw(st.sampled_from([np.uint8, np.uint16])))
    none = no_fruit_value(dtype)
    shape = draw(st.tuples(st.integers(1, 24), st.integers(1, 24)))
    ids = st.one_of(st.just(none), st.integers(0, max_fruit_id(dtype)), st.sampled_from([0, 254, 255, 256, 300]))
    return draw(arrays(dtype, shape, elements=ids.filter(lambda v: v <= none)))


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(mask=masks())
def test_any_mask_round_trips_through_the_writer_the_reader_and_the_validator(mask: np.ndarray, tmp_path: Path) -> None:
    write_view_files(tmp_path, "0001.jpeg", segmentation=mask)
    path = tmp_path / view_file_name("0001.jpeg", "mask")
    read = load_pixels(path, None)  # what View.mask() returns
    checked, problem = read_mask(path)  # what the validator checks
    assert problem is None and checked is not None
    for back in (read, checked):
        assert back.dtype == mask.dtype and np.array_equal(back, mask)
        assert np.array_equal(fruit_pixels(back), mask != no_fruit_value(mask))


def test_older_pillow_modes_of_16_bit_pngs_still_read() -> None:
    # Pillow before "I;16" for 16-bit PNGs gave mode "I" (int32).
    pixels = np.array([[0, 300], [65535, 7]], dtype=np.int32)
    mask, problem = mask_from_image("I", pixels)
    assert problem is None and mask is not None and mask.dtype == np.uint16 and mask.tolist() == pixels.tolist()
    assert as_mask(pixels).dtype == np.uint16
    assert mask_from_image("I", np.array([[70000]], np.int32))[1] is not None
    assert mask_from_image("RGB", np.zeros((2, 2, 3), np.uint8))[1] == (
        "must be a uint8 or uint16 single-channel PNG, got mode RGB"
    )
    assert as_mask(np.full((2, 2, 3), 9, np.uint8)).tolist() == [[9, 9], [9, 9]]  # a mask saved as RGB
