"""The algorithms' settings: PPO's zoo settings and the ``lin_X`` schedules they are written in."""

from __future__ import annotations

import re

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
    with pytest.raises(UserError, match=r"lin_X .X a number. is for learning_rate, clip_range, clip_range_vf only"):
        sb3_arguments(settings)


@pytest.mark.parametrize(
    "algo, values, message",
    [
        ("ppo", {"n_steps": "abc"}, "n_steps='abc': must be a number"),
        ("ppo", {"n_steps": -5}, "n_steps=-5: must be a whole number, at least 1"),
        ("ppo", {"batch_size": 2.5}, "batch_size=2.5: must be a whole number"),
        ("a2c", {"gamma": "yes"}, "gamma='yes': must be a number"),
        ("a2c", {"normalize_advantage": 1}, "normalize_advantage=1: must be true or false"),
        ("a2c", {"ent_coef": -0.1}, "ent_coef=-0.1: must not be negative"),
        ("dqn", {"learning_starts": float("nan")}, "learning_starts=nan: must be a number"),
    ],
)
def test_a_setting_sb3_would_crash_on_is_refused_before_training(algo: str, values: dict, message: str) -> None:
    """--set n_steps=abc or n_steps=-5 reached SB3 and crashed inside learn, after the
    environments were built; now one line names the setting."""
    from davis_ag.benchmark.algorithms import resolve_sb3_settings, resolve_settings

    with pytest.raises(UserError, match=re.escape(message)):
        resolve_settings(values) if algo == "a2c" else resolve_sb3_settings(algo, values)


def test_every_preset_and_sound_values_pass() -> None:
    from davis_ag.benchmark.algorithms import (
        SB3_SETTINGS,
        SETTINGS_PRESETS,
        check_setting_values,
    )

    for algo, chosen in SB3_SETTINGS.items():
        check_setting_values(algo, chosen)
    for chosen in SETTINGS_PRESETS.values():
        check_setting_values("a2c", chosen)
    check_setting_values("ppo", {"n_steps": 64, "batch_size": 64, "gamma": 1, "learning_rate": "lin_3e-4"})


def test_the_zoos_atari_a2c_resolves_to_sb3s_tf_like_rmsprop_and_16_environments() -> None:
    """RL Baselines3 Zoo's ``atari`` entry of hyperparams/a2c.yml, kept as JSON in the preset and
    built into SB3's own optimiser class only when the model is made."""
    import json

    from stable_baselines3.common.sb2_compat.rmsprop_tf_like import RMSpropTFLike

    from davis_ag.benchmark.algorithms import SETTINGS_PRESETS, environments_of, resolve_settings

    preset = resolve_settings("zoo-atari")
    assert json.loads(json.dumps(preset)) == preset  # a record's settings stay JSON
    assert preset["ent_coef"] == 0.01 and preset["vf_coef"] == 0.25 and preset["n_envs"] == 16
    arguments = sb3_arguments(preset)
    assert "n_envs" not in arguments  # the run's, never an argument of A2C
    assert arguments["policy_kwargs"] == {"optimizer_class": RMSpropTFLike, "optimizer_kwargs": {"eps": 1e-5}}
    assert SETTINGS_PRESETS["zoo-atari"]["policy_kwargs"]["optimizer_class"] == "RMSpropTFLike"
    # The set's own environments unless the run names others; the record says which ran.
    assert environments_of(dict(preset), None) == 16
    given = dict(preset)
    assert environments_of(given, 4) == 4 and given["n_envs"] == 4
    assert environments_of(resolve_settings("ours"), None) == 8


@pytest.mark.parametrize(
    "values, message",
    [
        ({"policy_kwargs": {"optimizer_class": "SGD"}}, "optimizer_class must be one of RMSpropTFLike"),
        ({"policy_kwargs": {"net_arch": [64]}}, "the network is --arch's"),
        ({"policy_kwargs": {"optimizer_kwargs": 3}}, "optimizer_kwargs must be a dict"),
        ({"n_envs": 0}, "n_envs=0: must be a whole number, at least 1"),
        ({"n_envs": 2.5}, "n_envs=2.5: must be a whole number"),
    ],
)
def test_an_optimiser_or_environments_sb3_cannot_take_are_refused_in_one_line(values: dict, message: str) -> None:
    from davis_ag.benchmark.algorithms import resolve_settings

    with pytest.raises(UserError, match=re.escape(message)):
        resolve_settings(values)


def test_train_offers_every_a2c_preset() -> None:
    from davis_ag.benchmark.algorithms import SETTINGS_PRESETS
    from davis_ag.cli import build_parser

    parser = build_parser()
    train = next(a for a in parser._subparsers._group_actions[0].choices["train"]._actions if a.dest == "a2c_settings")
    assert list(train.choices) == list(SETTINGS_PRESETS)
