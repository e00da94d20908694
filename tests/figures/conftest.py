"""One small real dataset for every figure test: a single-plant strawberry scene grown with Helios
and drawn on a 1.5 m staggered grid (7 positions x 3 altitudes, 128x72), without depth images (the
viewer test adds them to a copy), and an evaluation of it with every episode recorded. Skipped
where pyhelios cannot render natively."""

from __future__ import annotations

from pathlib import Path

import numpy as np
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


@pytest.fixture()
def tiny_world(sp_root: Path):
    """Four triangles of an exported scene's world, over the first scene of ``sp_root`` (its cameras):
    two of soil, a leaf and a fruit (id 0) of plant 0, each with its own colour."""
    from davis_ag.data.reader import open_dataset
    from davis_ag.render.scene_geometry import COLOUR, SceneGeometry
    from davis_ag.scene.organs import FRUIT, LEAF, ORGAN_NAMES, SOIL
    from davis_ag.worlds.triangles import NONE, WorldTriangles

    positions = np.array(
        [
            [[-1, -1, 0], [1, -1, 0], [1, 1, 0]],  # soil
            [[-1, -1, 0], [1, 1, 0], [-1, 1, 0]],  # soil
            [[0, 0, 0.1], [0.3, 0, 0.3], [0, 0.3, 0.3]],  # a leaf
            [[0.1, 0.1, 0.2], [0.2, 0.1, 0.2], [0.15, 0.15, 0.3]],  # a fruit
        ],
        dtype=np.float32,
    )
    n = len(positions)
    geometry = SceneGeometry(
        positions,
        np.zeros((n, 3, 2), np.float32),
        np.tile(np.float32([0, 0, 1]), (n, 3, 1)),
        np.arange(n, dtype=np.uint32),
        np.ones((n, 4), np.float32),
        np.full(n, -1, np.int32),
        np.full(n, COLOUR, np.int32),
        np.array([False, False, True, True]),
        np.zeros(n, bool),
    )
    return WorldTriangles(
        open_dataset(sp_root).scenes[0],
        geometry,
        np.array([SOIL, SOIL, LEAF, FRUIT], np.uint8),
        np.array([NONE, NONE, NONE, 0], np.int32),
        np.array([NONE, NONE, 0, 0], np.int32),
        np.array([[100, 80, 60], [100, 80, 60], [30, 160, 30], [200, 20, 20]], np.uint8),
        ORGAN_NAMES,
    )
