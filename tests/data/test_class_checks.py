"""A class image checked against its scene's own class table."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from davis_ag.data.class_checks import class_problems
from davis_ag.scene.organs import BARE_ORGAN_NAMES, ORGAN_NAMES, STRUCTURE


def test_a_structure_pixel_is_a_problem_only_where_the_scene_has_no_structure(tmp_path: Path) -> None:
    classes = np.zeros((4, 6), np.uint8)
    classes[1, 2] = STRUCTURE
    path = tmp_path / "0001_class.png"
    Image.fromarray(classes).save(path)
    assert class_problems(path, None, ORGAN_NAMES) == []
    (problem,) = class_problems(path, None, BARE_ORGAN_NAMES)
    assert "class values [9]" in problem and "table 0..8" in problem
    assert class_problems(path, np.full((4, 6), 255, np.uint8)) == []  # the whole table by default
