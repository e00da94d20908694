"""The paper's numbers, written here as the paper prints them (never read back from our code):
Table 1 (plants, altitudes), Table 2 (grids, actions), section III-B (slip), section III-C
(box thresholds and invalid moves) and section V-D (tau)."""

from __future__ import annotations

import numpy as np
import pytest

from davis_ag.benchmark.starts import min_pixels
from davis_ag.generate.one_scene import SceneRequest
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import CROPS, PAPER_PIXELS, SCENARIOS, SLIP_SIGMA

#: Table 1, in centimetres as printed: plant/trunk height, fruit radius, leaf length, altitudes.
TABLE_1_CM = {
    "strawberry": (40, 2.5, 10, (25, 40, 55)),
    "tomato": (100, 3, 20, (70, 110, 150)),
    "vine": (70, 0.75, 18, (50, 75, 100)),
}
#: Section III-C: "the minimum numbers of pixels for single strawberries, tomatoes, and grapes
#: were set to 210, 240, and 700"; the paper's images are 1280x720 (section III-A).
MIN_PIXELS_1280x720 = {"strawberry": 210, "tomato": 240, "vine": 700}
#: Section III-C: a move closer than 75 cm (strawberry) or 100 cm (others) to a plant is invalid.
EXCLUSION_CM = {"strawberry": 75, "tomato": 100, "vine": 100}


@pytest.mark.parametrize("crop", sorted(TABLE_1_CM))
def test_table_1(crop: str) -> None:
    height, radius, leaf, altitudes = TABLE_1_CM[crop]
    spec = CROPS[crop]
    assert spec.plant_height == pytest.approx(height / 100)
    assert spec.fruit_radius == pytest.approx(radius / 100)
    assert spec.leaf_length == pytest.approx(leaf / 100)
    assert spec.altitudes == pytest.approx(tuple(a / 100 for a in altitudes))
    assert spec.exclusion_radius == pytest.approx(EXCLUSION_CM[crop] / 100)


def test_table_2_and_section_iii_b_grids() -> None:
    sp, mp = SCENARIOS["sp"], SCENARIOS["mp"]
    # Table 2: step 25 cm / 50 cm; 3 / 2 heights (MP: the highest and the lowest); 1 / 12 angles
    # (every 30 degrees); 6 / 8 actions (besides done).
    assert (sp.step, len(sp.altitude_levels), sp.headings, len(sp.actions)) == (0.25, 3, 1, 6)
    assert (mp.step, mp.altitude_levels, mp.headings, len(mp.actions)) == (0.50, (0, 2), 12, 8)
    assert 360 / mp.headings == 30
    # Section III-B: 3 m x 3 m for SP, 7 m x 3 m for MP; slip sigma 2.5 cm on x and y.
    assert sp.extent == (3.0, 3.0) and mp.extent == (7.0, 3.0)
    assert SLIP_SIGMA == 0.025


def test_section_v_c_tau() -> None:
    # "SP ... with time steps tau=3, whereas MP ... with tau=5".
    assert (SCENARIOS["sp"].tau, SCENARIOS["mp"].tau) == (3, 5)


@pytest.mark.parametrize("crop", sorted(MIN_PIXELS_1280x720))
@pytest.mark.parametrize(
    "size, area_ratio", [((1280, 720), 1), ((640, 360), 1 / 4), ((2560, 1440), 4), ((96, 54), 96 * 54 / (1280 * 720))]
)
def test_box_thresholds_scale_with_image_area(crop: str, size: tuple[int, int], area_ratio: float) -> None:
    assert CROPS[crop].min_fruit_pixels == MIN_PIXELS_1280x720[crop]
    request = SceneRequest(SCENARIOS["sp"], CROPS[crop], 0, 0, Camera(*size))
    # A whole number of pixels: the paper's threshold times the area ratio, rounded (at least 1).
    assert abs(request.min_fruit_pixels - max(1.0, MIN_PIXELS_1280x720[crop] * area_ratio)) <= 0.5
    assert PAPER_PIXELS == 1280 * 720
    assert request.min_fruit_pixels == CROPS[crop].min_fruit_pixels_at(*size)


def test_environment_threshold_without_scene_json_scales_the_same_way() -> None:
    class Scene:  # the original download: no scene.json, crop from the folder name
        metadata = None
        id = "Single-Tomato/000"
        crop = "tomato"
        scenario = "sp"

    class Cache:
        image_size = (640, 360)

    assert min_pixels(Scene(), Cache()) == pytest.approx(240 / 4) == CROPS["tomato"].min_fruit_pixels_at(640, 360)
    assert np.isclose(min_pixels(Scene(), type("C", (), {"image_size": (1280, 720)})()), 240)
