"""A greenhouse row with and without its structure, end to end at a reduced size: the strings and
pipe rails are drawn and labelled, recorded in scene.json and made again from it; without them the
scene is the bare row of before (no new field, the old class table, the same plants and views).
The greenhouse's floor cover is drawn white where the bare row's soil is brown."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from davis_ag.scene.organs import BARE_ORGAN_NAMES, ORGAN_NAMES, SOIL, STRUCTURE
from real_scenes import generate_config

pytestmark = pytest.mark.slow

#: A capsicum row (the cheapest row with a structure: 30 small plants), two headings, one camera
#: line in each alley.
ROW = """\
seed: 2
image_size: 128x72
grid: {{step: 1.0, headings: 2}}
structures: {structures}
groups:
  - {{scenario: row, crop: capsicum, scenes: 1}}
"""
SCENE = "Row-Capsicum/000"


@pytest.fixture(scope="module")
def rows(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    return {s: generate_config(tmp_path_factory, f"row-{s}", ROW.format(structures=s)) for s in ("default", "none")}


def _classes(root: Path) -> np.ndarray:
    from davis_ag.data.reader import open_dataset

    scene = open_dataset(root).scene(SCENE)
    return np.concatenate([view.classes().ravel() for view in scene])


def test_the_structure_is_drawn_labelled_and_recorded(rows: dict[str, Path]) -> None:
    from davis_ag.data.validate import validate_dataset

    root = rows["default"]
    report = validate_dataset(root, workers=1)
    assert report.ok, report.problems[:5]
    scene = json.loads((root / SCENE / "scene.json").read_text())
    assert scene["structures"] == "default"
    assert scene["classes"]["table"] == list(ORGAN_NAMES)
    assert json.loads((root / "dataset.json").read_text())["groups"]["Row-Capsicum"]["structures"] == "default"
    assert np.count_nonzero(_classes(root) == STRUCTURE) > 0
    # the greenhouse's white floor cover where the bare row shows brown soil
    assert _soil_brightness(root) > _soil_brightness(rows["none"]) + 60


def _soil_brightness(root: Path) -> float:
    from davis_ag.data.reader import open_dataset

    scene = open_dataset(root).scene(SCENE)
    pixels = [view.image()[view.classes() == SOIL] for view in scene]
    return float(np.concatenate(pixels).mean())


def test_without_structures_the_scene_is_the_bare_row_of_before(rows: dict[str, Path]) -> None:
    bare = json.loads((rows["none"] / SCENE / "scene.json").read_text())
    built = json.loads((rows["default"] / SCENE / "scene.json").read_text())
    assert "structures" not in bare
    assert "structures" not in json.loads((rows["none"] / "dataset.json").read_text())["groups"]["Row-Capsicum"]
    assert bare["classes"]["table"] == list(BARE_ORGAN_NAMES)
    assert "9 structure" not in bare["conventions"]["classes"]
    assert not np.any(_classes(rows["none"]) == STRUCTURE)
    # The structure draws nothing from the scene's seed: the same plants, fruit, sun and views.
    for key in ("plants", "fruits", "lighting", "views"):
        assert bare[key] == built[key], key


def test_a_structured_scene_is_made_again_byte_for_byte_from_its_records(rows: dict[str, Path]) -> None:
    from davis_ag.generate.regenerate import request_for, verify_scene

    assert request_for(rows["default"] / SCENE).structures == "default"
    assert request_for(rows["none"] / SCENE).structures == "none"
    verdict = verify_scene(rows["default"] / SCENE, progress=False)
    assert verdict.identical, verdict.text()
