"""Randomised appearance: drawn from the scene seed alone, inside its ranges, labels untouched."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from davis_ag.errors import UserError
from davis_ag.scene import appearance as ap
from davis_ag.scene.lighting import Lighting

PAPER_SUN = Lighting(sun_elevation=50.0, sun_azimuth=120.0)


def test_paper_appearance_changes_nothing() -> None:
    paper = ap.draw_appearance("paper", 7)
    assert paper.lighting(PAPER_SUN) is PAPER_SUN and PAPER_SUN.is_paper
    assert paper.soil == "dirt.jpg" and paper.noise_sigma == 0.0


@settings(max_examples=50, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_random_draws_come_from_the_seed_and_stay_in_range(seed: int) -> None:
    first, again = ap.draw_appearance("random", seed), ap.draw_appearance("random", seed)
    assert first == again
    assert first.soil in ap.SOILS and first.sky in ap.SKIES
    assert ap.SUN_ELEVATION[0] <= first.sun_elevation <= ap.SUN_ELEVATION[1]
    assert 0.0 <= first.sun_azimuth < 360.0
    assert ap.SUN_STRENGTH[0] <= first.sun_strength <= ap.SUN_STRENGTH[1]
    assert ap.EXPOSURE[0] <= first.exposure <= ap.EXPOSURE[1]
    red, green, blue = first.white_balance
    assert green == 1.0 and red + blue == pytest.approx(2.0) and abs(red - 1.0) <= ap.WHITE_BALANCE_SHIFT
    assert ap.NOISE_SIGMA[0] <= first.noise_sigma <= ap.NOISE_SIGMA[1]


def test_different_scenes_look_different() -> None:
    draws = [ap.draw_appearance("random", seed) for seed in range(40)]
    assert len({d.soil for d in draws}) == len(ap.SOILS) and len({d.sky for d in draws}) == len(ap.SKIES)
    assert len({round(d.exposure, 6) for d in draws}) == 40


def test_random_lighting_keeps_the_scene_and_replaces_the_sun() -> None:
    pytest.importorskip("pyhelios")
    drawn = ap.draw_appearance("random", 11)
    lighting = drawn.lighting(PAPER_SUN)
    assert (lighting.sun_elevation, lighting.sun_azimuth) == (drawn.sun_elevation, drawn.sun_azimuth)
    assert lighting.sky_texture.endswith(drawn.sky) and not lighting.is_paper
    assert lighting.exposure == drawn.exposure and lighting.white_balance == drawn.white_balance
    assert (lighting.noise_sigma, lighting.noise_seed) == (drawn.noise_sigma, 11)
    summary = drawn.summary()
    assert summary["mode"] == "random" and "seed" not in summary and summary["noise"].startswith("gaussian")


def test_unknown_appearance_is_one_clear_error() -> None:
    with pytest.raises(UserError, match="choose paper or random"):
        ap.resolve_appearance("sunny")
    assert ap.resolve_appearance(None) == "paper" and ap.resolve_appearance(" Random ") == "random"


def test_random_appearance_needs_our_renderer_and_flows_from_configs() -> None:
    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.generate.run_config import parse_dataset_config, single_group_config
    from davis_ag.scene.specs import CROPS, SCENARIOS

    with pytest.raises(UserError, match="needs our renderer"):
        SceneRequest(SCENARIOS["sp"], CROPS["strawberry"], 0, 0, renderer="helios", appearance="random")
    config = parse_dataset_config("appearance: random\ngroups: [{scenario: sp, crop: strawberry, scenes: 1}]", "t")
    assert {r.appearance for r in config.requests()} == {"random"}
    assert single_group_config("sp", "strawberry", 1, 0, 0, (64, 36)).requests()[0].appearance == "paper"
    with pytest.raises(UserError, match="appearance"):
        parse_dataset_config("appearance: sunny\ngroups: [{scenario: sp, crop: strawberry, scenes: 1}]", "t")
