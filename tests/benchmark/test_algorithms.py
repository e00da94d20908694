"""The algorithms' settings: PPO's zoo settings and the ``lin_X`` schedules they are written in."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from davis_ag.benchmark.algorithms import SB3_SETTINGS, sb3_arguments
from davis_ag.errors import UserError


def test_ppo_trains_with_the_zoos_atari_settings() -> None:
    """RL Baselines3 Zoo's ``atari`` entry of hyperparams/ppo.yml, value for value."""
    assert SB3_SETTINGS["ppo"] == {
        "n_steps": 128,
        "n_epochs": 4,
        "batch_size": 256,
        "learning_rate": "lin_2.5e-4",
        "clip_range": "lin_0.1",
        "vf_coef": 0.5,
        "ent_coef": 0.01,
    }


@settings(deadline=None)  # the first example imports Stable-Baselines3 (about a second)
@given(start=st.floats(min_value=1e-8, max_value=10.0), remaining=st.floats(min_value=0.0, max_value=1.0))
def test_a_lin_value_falls_linearly_from_its_number_to_zero(start: float, remaining: float) -> None:
    """SB3 calls a schedule with the fraction of the run left: 1 at the start, 0 at the end."""
    schedule = sb3_arguments({"learning_rate": f"lin_{start!r}", "n_steps": 8})
    assert schedule["n_steps"] == 8
    assert schedule["learning_rate"](1.0) == pytest.approx(start)
    assert schedule["learning_rate"](remaining) == pytest.approx(start * remaining, abs=1e-12)


@pytest.mark.parametrize("settings", [{"learning_rate": "lin_fast"}, {"n_epochs": "lin_4"}, {"clip_range": "lin_"}])
def test_a_lin_value_that_is_no_number_or_no_schedule_is_refused_in_one_line(settings: dict[str, str]) -> None:
    with pytest.raises(UserError, match="lin_X .X a number. is for learning_rate, clip_range, clip_range_vf only"):
        sb3_arguments(settings)
