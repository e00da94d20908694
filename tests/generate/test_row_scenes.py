"""A plant-library crop's row, end to end at a reduced size: generated with Helios, validated,
read back, and played by the benchmark with MP's tau, actions and headings."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from davis_ag.scene.specs import CROPS
from real_scenes import generate_config

pytestmark = pytest.mark.slow

#: An almond orchard's row, four headings, one camera line in each alley: the fewest trees of any
#: row (one in the segment and its two neighbours, in three rows: 9 trees, where olive needs 18).
ROW = """\
seed: 3
image_size: 128x72
depth: false
grid: {step: 1.0, headings: 4}
groups:
  - {scenario: row, crop: almond, scenes: 1}
"""


@pytest.fixture(scope="module")
def row_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return generate_config(tmp_path_factory, "row", ROW)


def test_the_row_validates_and_records_its_three_rows_of_plants(row_root: Path) -> None:
    from davis_ag.data.validate import validate_dataset

    report = validate_dataset(row_root, workers=1)
    assert report.ok, report.problems[:5]
    scene = json.loads((row_root / "Row-Almond/000/scene.json").read_text())
    row = CROPS["almond"].row
    assert len(scene["plants"]) == 3 * (row.plants + 2)
    ys = sorted({round(p["position"][1], 3) for p in scene["plants"]})
    assert ys == [-row.row_spacing, 0.0, row.row_spacing]
    assert all(p["library"]["model"] == "almond" for p in scene["plants"])
    assert len(scene["fruits"]) == sum(p["fruit_count"] for p in scene["plants"])
    # Cameras stand in the alleys only, on both sides.
    sides = {view["nominal"][1] > 0 for view in scene["views"].values()}
    assert sides == {True, False}
    assert all(abs(view["nominal"][1]) > row.exclusion_band for view in scene["views"].values())


def test_the_benchmark_plays_the_row_with_mp_moves_and_tau(row_root: Path) -> None:
    from davis_ag.benchmark import TVMEnv
    from davis_ag.benchmark.agents import build_agents
    from davis_ag.benchmark.evaluation import evaluate_policies

    env = TVMEnv(row_root, scenario="row", split="all", max_start_oer=1.01)
    assert env.action_space.n == 9  # MP's eight moves and done
    results = evaluate_policies(env, build_agents(["Rand", "Oracle"]), episodes=6, sessions=1, seed=0).as_json()
    env.close()
    lengths = [row["length"]["mean"] for row in results["policies"].values()]
    assert all(0 < length <= 5 for length in lengths)
    assert results["policies"]["Oracle"]["oer_tau"]["mean"] >= results["policies"]["Rand"]["oer_tau"]["mean"]


def test_a_row_scenes_settings_read_back_with_the_rows_camera_heights(row_root: Path) -> None:
    """scene.json of a row holds the row's camera heights, not the crop's single-plant ones: reading it
    back (what regrowing, views on demand and `verify SCENE` start from) must find them."""
    from davis_ag.generate.recorded_settings import read_settings
    from davis_ag.scene.specs import camera_altitudes

    settings = read_settings(row_root / "Row-Almond/000")
    assert settings.scenario.name == "row"
    recorded = json.loads((row_root / "Row-Almond/000/scene.json").read_text())["grid"]["altitudes_m"]
    assert camera_altitudes(settings.scenario, settings.crop) == recorded
