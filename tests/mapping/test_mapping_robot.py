"""Row mapping with a robot: only the views it reaches, every move in its seconds, the seconds to
50 % and 80 % of what the alley can see, and the file replayed."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from davis_ag.mapping.env import RowMappingEnv
from davis_ag.mapping.evaluation import evaluate_mapping, replay_mapping
from davis_ag.mapping.results import mapping_table
from real_scenes import ROBOT_VINE, generate_config

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return generate_config(tmp_path_factory, "vine", ROBOT_VINE)


def test_a_robot_maps_only_what_it_reaches_in_its_seconds(root: Path) -> None:
    env = RowMappingEnv(root, "sp", split="all", robot="ur5-trolley", budget=8)
    reachable = env.robot.reaches[0].reachable
    names = env.caches[0].view_names
    for seed in range(5):
        _, info = env.reset(seed=seed)
        while True:
            assert reachable[names.index(info["path"][-1])]
            _, _, over, _, info = env.step(int(np.random.default_rng(seed).integers(env.action_space.n)))
            assert (info["robot"]["seconds"] > 0) == (not info["refused"])
            if over:
                break
    results = evaluate_mapping([], root, "sp", "all", 1, 6, 0, budget=8, robot="ur5-trolley")
    greedy = results.policies["Greedy"]
    assert greedy.seconds is not None and greedy.seconds.mean > 0
    for episode in greedy.episodes:
        assert episode.step_seconds is not None and len(episode.step_seconds) == len(episode.actions)
        assert sum(episode.step_seconds) == pytest.approx(episode.seconds)
    if greedy.moves_50 is not None:
        assert greedy.seconds_50 is not None and greedy.seconds_50 > 0
    assert "seconds to 50 %" in mapping_table(results) and results.protocol.robot["name"] == "ur5-trolley"
    assert replay_mapping(results, root, "robot.json").sound
