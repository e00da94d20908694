"""One small real dataset for every figure test: a single-plant strawberry scene grown with Helios
and drawn on a 1.5 m staggered grid (7 positions x 3 altitudes, 128x72), without depth images (the
viewer test adds them to a copy), and an evaluation of it with every episode recorded. Skipped
where pyhelios cannot render natively."""

from __future__ import annotations

from pathlib import Path

import pytest

from davis_ag.errors import UserError

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
    from davis_ag.generate.run_config import load_dataset_config
    from davis_ag.generate.run_progress import RunOptions
    from davis_ag.generate.runner import run_dataset
    from davis_ag.scene.plants import require_native_helios

    try:
        require_native_helios()
    except UserError as error:
        pytest.skip(str(error))
    folder = tmp_path_factory.mktemp("real")
    config = folder / "tiny.yaml"
    config.write_text(TINY_REAL)
    root = folder / "data"
    run_dataset(load_dataset_config(config).requests(), root, RunOptions(workers=1, progress=False))
    return root


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
