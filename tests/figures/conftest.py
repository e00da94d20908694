"""One small real dataset for every figure test: a single-plant strawberry scene grown with Helios
and drawn on a 1.5 m staggered grid (7 positions x 3 altitudes, 128x72), without depth images (the
viewer test adds them to a copy), and an evaluation of it with every episode recorded. Skipped
where pyhelios cannot render natively."""

from __future__ import annotations

from pathlib import Path

import pytest

from real_scenes import generate_config

TINY_REAL = """\
seed: 5
image_size: 128x72
depth: false
grid: {extent: [3.0, 3.0], step: 1.5}
groups:
  - {scenario: sp, crop: strawberry, scenes: 1}
"""


@pytest.fixture(scope="session")
def real_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The dataset root of the tiny real scene."""
    return generate_config(tmp_path_factory, "real", TINY_REAL)


@pytest.fixture(scope="session")
def real_results(real_root: Path) -> Path:
    """``davis-ag evaluate``'s results on the tiny scene (every policy, episodes recorded)."""
    from davis_ag.benchmark import TVMEnv
    from davis_ag.benchmark.agents import build_agents
    from davis_ag.benchmark.evaluation import evaluate_policies, write_json

    env = TVMEnv(real_root, scenario="sp", split="all", max_start_oer=1.01)
    results = evaluate_policies(
        env, build_agents(["LRD", "UDD", "Rand", "Oracle"]), episodes=12, sessions=2, seed=0, keep_episodes=True
    ).as_json()
    env.close()
    return write_json(results, real_root.parent / "results.json")
