"""The dataset's file layout: names round-trip, depth survives its encoding, files land where the reader looks."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from davis_ag.errors import UserError
from davis_ag.formats.layout import (
    DEPTH_MAX_MM,
    VIEW_FILES,
    decode_depth,
    encode_depth,
    read_depth,
    view_file,
    view_file_name,
    view_of_file,
    write_view_files,
)


@given(st.integers(1, 999_999), st.sampled_from(sorted(VIEW_FILES)))
def test_every_view_file_names_its_view_and_kind(number: int, kind: str) -> None:
    name = f"{number:04d}.jpeg"
    assert view_of_file(view_file_name(name, kind)) == (name, kind)


def test_the_published_names() -> None:
    assert view_file_name("0001.jpeg", "mask") == "0001_seg.png"
    assert view_file(Path("scene"), "0001.jpeg", "depth") == Path("scene/images/0001_depth.png")
    assert view_of_file("0001.jpg") == ("0001.jpeg", "image")  # the original download's spellings
    assert view_of_file("notes.txt") is None


@given(arrays(np.float64, (3, 4), elements=st.floats(0, 70.0)))
def test_depth_survives_encoding_to_the_millimetre(metres: np.ndarray) -> None:
    back = decode_depth(encode_depth(metres))
    assert back.dtype == np.float32
    assert np.all(np.abs(back - np.minimum(metres, DEPTH_MAX_MM / 1000)) <= 0.0005 + 1e-6)


def test_written_files_read_back(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    colour = rng.integers(0, 255, (6, 8, 3), dtype=np.uint8)
    segmentation = np.full((6, 8), 255, np.uint8)
    segmentation[2:4, 3:5] = 7
    depth = rng.uniform(0.2, 3.0, (6, 8))
    written = write_view_files(tmp_path, "0003.jpeg", colour, segmentation, depth)
    assert written == ["0003.jpeg", "0003_seg.png", "0003_depth.png"]
    assert np.allclose(read_depth(tmp_path / "0003_depth.png"), depth, atol=0.0006)
    (tmp_path / "0004_depth.png").write_bytes(b"not a png")
    with pytest.raises(UserError, match=r"0004_depth.png: cannot decode"):
        read_depth(tmp_path / "0004_depth.png")
