"""RowMapping-v0: Gymnasium's checker, rewards recounted from the files, the budget, refused moves."""

from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import davis_ag  # noqa: F401 - registers the environments
from davis_ag.errors import UserError
from davis_ag.mapping.env import CURRENT, RowMappingEnv
from layout_factory import write_tiny_dataset


@pytest.fixture(scope="module")
def tiny_mp(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_tiny_dataset(tmp_path_factory.mktemp("mp"), "mp", "vine", scenes=2)


def test_it_passes_gymnasiums_checker(tiny_mp: Path) -> None:
    env = gym.make("davis_ag/RowMapping-v0", dataset=tiny_mp, scenario="mp", split="all")
    check_env(env.unwrapped)
    assert env.unwrapped.action_names[-1] == "rotate_ccw"  # no done: the budget ends an episode


def _recount(root: Path, scene_id: str, path: list[str], fraction: float) -> list[int]:
    """Fruit first seen at each view of a path, from scene.json and annotations.json alone."""
    raw = json.loads((root / scene_id / "scene.json").read_text())
    boxed = json.loads((root / scene_id / "annotations.json").read_text())
    seen: set[int] = set()
    counts = []
    for name in path:
        ids = {b[4] for b in boxed[name]["bounding_boxes"]}
        here = {int(f) for f, v in raw["visible_fraction"][name].items() if v >= fraction and int(f) in ids}
        counts.append(len(here - seen))
        seen |= here
    return counts


def test_rewards_are_the_fruit_first_seen_recounted_from_the_files(tiny_mp: Path) -> None:
    env = RowMappingEnv(tiny_mp, scenario="mp", split="all", budget=12)
    for seed in range(6):
        _, info = env.reset(seed=seed)
        rewards, rng = [], np.random.default_rng(seed)
        while True:
            _, reward, terminated, truncated, info = env.step(int(rng.integers(env.action_space.n)))
            rewards.append(reward)
            assert not truncated
            if terminated:
                break
        fruit = info["fruit"]
        counts = _recount(tiny_mp, info["scene"], info["path"], 0.5)
        assert len(info["seen"]) == sum(counts)
        assert np.allclose(np.array(rewards) * fruit, counts[1:])  # the start's fruit earn nothing
        assert info["coverage"] == pytest.approx(sum(counts) / fruit)
        assert info["steps"] == 12 == len(info["path"]) - 1


def test_a_move_with_no_view_stays_and_costs_a_step(tiny_mp: Path) -> None:
    env = RowMappingEnv(tiny_mp, scenario="mp", split="all", budget=3)
    scene = env.scenes[0]
    table = env.caches[0].pointers
    # A view from which "up" leads nowhere (the top altitude).
    view = int(np.flatnonzero(table[:, env.action_names.index("up")] < 0)[0])
    _, info = env.reset(options={"start": (scene.id, env.caches[0].view_names[view])})
    _, reward, terminated, _, info = env.step(env.action_for("up"))
    assert info["refused"] and reward == 0.0 and not terminated
    assert info["path"] == [env.caches[0].view_names[view]] * 2 and info["steps"] == 1


def test_the_memory_channel_marks_where_the_camera_is_and_has_been(tiny_mp: Path) -> None:
    env = RowMappingEnv(tiny_mp, scenario="mp", split="all")
    obs, _ = env.reset(seed=1)
    assert obs.shape == (224, 224, 4) and (obs[:, :, 3] == CURRENT).any()
    assert np.array_equal(obs[:, :, :3], env.caches[env.scene_index].images[env.current_view, :, :, :3])
    moved = next(
        a for a in range(env.action_space.n) if env.next_views[env.scene_index][env.current_view, a] != env.current_view
    )
    obs, *_ = env.step(moved)
    assert (obs[:, :, 3] == 96).any() and (obs[:, :, 3] == CURRENT).any()


def test_the_same_seed_gives_the_same_start(tiny_mp: Path) -> None:
    a = RowMappingEnv(tiny_mp, scenario="mp", split="all")
    b = RowMappingEnv(tiny_mp, scenario="mp", split="all")
    assert [a.reset(seed=s)[1]["path"] for s in range(5)] == [b.reset(seed=s)[1]["path"] for s in range(5)]


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"budget": 0}, "budget must be at least 1"),
        ({"budget_s": 10.0}, "needs a robot"),
        ({"seen_fraction": 0.0}, "outside"),
        ({"render_mode": "human"}, "render_mode"),
    ],
)
def test_bad_settings_are_one_line(tiny_mp: Path, kwargs: dict, message: str) -> None:
    with pytest.raises(UserError, match=message):
        RowMappingEnv(tiny_mp, scenario="mp", split="all", **kwargs)


def test_a_step_after_the_end_and_a_bad_action_are_refused(tiny_mp: Path) -> None:
    env = RowMappingEnv(tiny_mp, scenario="mp", split="all", budget=1)
    env.reset(seed=0)
    with pytest.raises(UserError, match="invalid action"):
        env.step(99)
    env.step(0)
    with pytest.raises(UserError, match="episode is over"):
        env.step(0)
