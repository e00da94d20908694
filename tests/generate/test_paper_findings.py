"""The paper's findings on a generated single-plant strawberry scene (sections IV and V-D).

One real scene: real Helios plants, the paper's grid thinned to every 0.5 m (90 of its 285
views, every altitude kept), drawn at the paper's 1280x720.
Section IV (Fig. 2) shows one strawberry plant with 24 fruit whose visible-fruit count ranges
from fewer than 5 to 16 or more across positions, no view seeing all 24; Fig. 3 shows that
changing altitude at a fixed position both loses and gains fruit. Section V-D: the OER of SP
strawberry boxes is right-skewed, 4 % of them below 0.4 (davis-ag scene-stats measures this
over several scenes; docs/scenes.md has the result).

Fig. 2 counts a fruit as visible when Helios's Synthetic Annotation plug-in would box it (10
pixels, ``specs.SEEABLE_FRUIT_PIXELS``); the OER share is over the published boxes, those of at
least the crop's 210 pixels (section III-C). The scene is generated once with the lower
threshold and its boxes are split by their visible pixels.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from davis_ag.errors import UserError
from davis_ag.generate.one_scene import SceneRequest, generate_scene
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import CROPS, SEEABLE_FRUIT_PIXELS, scenario_spec

#: The paper's image size: a strawberry 2.5 cm wide covers a few hundred pixels at a metre.
CAMERA = Camera(1280, 720)
STRAWBERRY = CROPS["strawberry"]
#: Scene 3 of dataset seed 0, as `davis-ag generate --crop strawberry` grows it: the first scene
#: whose plant carries about the paper's 24 fruit (section IV): 22. The Canopy Generator's
#: strawberry bears a fruit on each of its 50 stems with probability 0.6, 30 on average; scenes
#: 0-2 carry 27, 29 and 35, and none of the first 40 exactly 24. On the paper's 2.5 x 2.5 m
#: lattice every 0.5 m: 30 positions at each of the three altitudes. Every fruit the plug-in
#: would box is boxed.
GRID = replace(scenario_spec("sp", STRAWBERRY), step=0.5)
REQUEST = SceneRequest(GRID, replace(STRAWBERRY, min_fruit_pixels=SEEABLE_FRUIT_PIXELS), 3, 0, CAMERA)
#: Section IV: the showcase plant's fruit, and how far from it our test plant may be.
PAPER_FRUIT = 24
FRUIT_SLACK = 2
POSITIONS = 30


#: One real scene grown and drawn at the paper's grid: over 20 s.
pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def scene(tmp_path_factory: pytest.TempPathFactory) -> dict:
    """Per view: the fruit ids boxed; plus the scene's fruit count and box OERs."""
    from davis_ag.benchmark.cache import load_scene_cache
    from davis_ag.data.reader import open_dataset
    from davis_ag.scene.plants import require_native_helios

    try:
        require_native_helios()
    except UserError as error:
        pytest.skip(str(error))
    root = tmp_path_factory.mktemp("findings")
    scene_dir, _ = generate_scene(REQUEST, root)
    meta = json.loads((scene_dir / "scene.json").read_text())
    opened = open_dataset(root).scene(REQUEST.folder)
    seen = {tuple(meta["views"][v.name]["grid"][:3]): {b.fruit_id for b in v.boxes} for v in opened}
    cache = load_scene_cache(opened, Path(root))
    published = cache.box_pixels >= STRAWBERRY.min_fruit_pixels
    return {
        "seen": seen,
        "fruit": len(meta["fruits"]),
        "plants": meta["plants"],
        "oer": np.asarray(cache.box_oer[published], dtype=float),
    }


def test_the_plant_carries_as_many_fruit_as_the_papers(scene: dict) -> None:
    # Section IV: 24 fruit (other plants spread around it: docs/scenes.md, min / median / max).
    assert abs(scene["fruit"] - PAPER_FRUIT) <= FRUIT_SLACK
    assert len(scene["seen"]) == POSITIONS * 3


def test_visible_fruit_range_from_fewer_than_5_to_16_or_more(scene: dict) -> None:
    # Fig. 2: a few steps apart, fewer than 5 or 16 and more of the 24 fruit are in view.
    counts = [len(ids) for ids in scene["seen"].values()]
    assert min(counts) < 5 and max(counts) >= 16


def test_no_view_sees_every_fruit(scene: dict) -> None:
    assert max(len(ids) for ids in scene["seen"].values()) < scene["fruit"]


def test_changing_altitude_both_loses_and_gains_fruit(scene: dict) -> None:
    seen = scene["seen"]
    pairs = [(low, seen[ix, iy, level + 1]) for (ix, iy, level), low in seen.items() if (ix, iy, level + 1) in seen]
    assert len(pairs) == POSITIONS * 2  # the same positions at every altitude
    # Fig. 3: going up hides fruit seen below at some positions and reveals new ones at others,
    # and at many positions both happen.
    loses = sum(bool(low - high) for low, high in pairs)
    gains = sum(bool(high - low) for low, high in pairs)
    both = sum(bool(low - high) and bool(high - low) for low, high in pairs)
    assert loses >= len(pairs) // 4 and gains >= len(pairs) // 4 and both > 0


def test_oer_is_right_skewed(scene: dict) -> None:
    oer = scene["oer"]
    assert len(oer) > 150  # enough published boxes for a share of a few per cent to mean something
    # Section V-D: right-skewed as the paper uses it: the mass at high OER with a tail towards 0,
    # i.e. a negative third standardised moment (median against mean, the proxy used before,
    # differs by less than 0.01 on these distributions and so decides nothing: docs/scenes.md).
    centred = oer - oer.mean()
    assert np.mean(centred**3) / np.mean(centred**2) ** 1.5 < -0.1


@pytest.mark.xfail(
    strict=True,
    reason="a known gap: the Canopy Generator strawberry as we rebuild it puts 0.4 % "
    "of this scene's published boxes below OER 0.4 (paper: 4 %); the share over 10 scenes is in "
    "docs/scenes.md. Strict: when the plants meet the paper, this test says so.",
)
def test_few_boxes_below_0_4_as_in_the_paper(scene: dict) -> None:
    # Section V-D: 4 % below 0.4. One scene varies more than several (davis-ag scene-stats
    # measures those, 2-8 % asked): 1-8 % here.
    assert 0.01 <= (scene["oer"] < 0.4).mean() <= 0.08
