"""What the detector sees of an export's boxes: their median side at the training image size."""

from __future__ import annotations

from pathlib import Path

import pytest
from PIL import Image

from davis_ag.detection.yolo_training import FINEST_STRIDE, median_box_side


def _export(root: Path, size: tuple[int, int], boxes: list[tuple[float, float]]) -> Path:
    (root / "images" / "train").mkdir(parents=True)
    (root / "labels" / "train").mkdir(parents=True)
    Image.new("RGB", size).save(root / "images" / "train" / "0000.jpg")
    lines = [f"0 0.5 0.5 {w} {h}" for w, h in boxes]
    (root / "labels" / "train" / "0000.txt").write_text("\n".join(lines) + "\n")
    return root


def test_boxes_are_measured_as_the_detector_sees_them(tmp_path: Path) -> None:
    # 320x180 views: a 16 x 18 px box; at --imgsz 640 the long side doubles, so ~34 px.
    export = _export(tmp_path / "a", (320, 180), [(0.05, 0.1), (0.05, 0.1), (0.5, 0.5)])
    assert median_box_side(export, "train", 640) == pytest.approx((16 * 18) ** 0.5 * 2)
    assert median_box_side(export, "test", 640) is None  # no such split


def test_the_stand_in_sizes_that_taught_nothing_fall_under_the_grid(tmp_path: Path) -> None:
    """The stand-in transfer run at 320x180 had boxes of 5 px: under the detector's 8 px grid,
    where pre-training learnt next to nothing; the run now says so."""
    export = _export(tmp_path / "b", (320, 180), [(5 / 320, 5 / 180)] * 3)
    assert median_box_side(export, "train", 320) < FINEST_STRIDE <= median_box_side(export, "train", 640)
