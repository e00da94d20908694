"""The per-scene gap chart: one dot per scene and learner, the mean and its intervals, as PNG."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

from davis_ag.figures.result_charts import plot_scene_gaps


def gap(mean: float, scenes: list[tuple[str, float, int]], over_scenes: tuple[float, float] | None) -> dict:
    per_scene = [{"scene": s, "gap": g, "episodes": e, "starts": e} for s, g, e in scenes]
    low, high = over_scenes or (None, None)
    return {"gap": mean, "low": mean - 0.01, "high": mean + 0.01, "episodes": 60, "per_scene": per_scene,
            "scene_low": low, "scene_high": high}  # fmt: skip


def test_the_chart_draws_every_learner_over_the_scenes_it_played(tmp_path: Path) -> None:
    scenes = [(f"Single-Strawberry/{i:03d}", g, 5 + i) for i, g in enumerate((0.1, -0.05, 0.02, 0.0))]
    gaps = {"A2C": gap(0.02, scenes, (-0.03, 0.07)), "PPO": gap(-0.01, scenes[:3], None)}  # PPO: no scene interval
    path = plot_scene_gaps(gaps, tmp_path / "gaps.png", "sp-strawberry, test split")
    picture = np.asarray(Image.open(path).convert("RGB")).astype(int)
    assert picture.shape[1] > picture.shape[0] > 200
    # Both learners' colours (matplotlib's C0 blue and C1 orange) are drawn.
    for colour in ((31, 119, 180), (255, 127, 14)):
        assert (np.abs(picture - colour).sum(axis=2) < 40).sum() > 50, colour


def test_the_ladder_draws_each_group_and_grows_with_them(tmp_path: Path) -> None:
    from davis_ag.figures.result_charts import plot_ladder

    def row(label: str, best: float, learners: dict) -> dict:
        return {
            "label": label,
            "oer_0": 0.3,
            "rand": best - 0.01,
            "best_fixed": best,
            "oracle": 0.9,
            "learners": learners,
        }

    scored = {"A2C": {"mean": 0.5, "low": 0.01, "high": 0.05}, "PPO": {"mean": 0.45}}  # PPO: no paired interval
    rows = [row("apple-wall row", 0.33, scored), row("olive sp", 0.49, {})]  # a group with no learner yet
    few = np.asarray(Image.open(plot_ladder(rows, tmp_path / "few.png", "two")).convert("RGB")).astype(int)
    many = np.asarray(Image.open(plot_ladder(rows * 5, tmp_path / "many.png", "ten")).convert("RGB")).astype(int)
    assert many.shape[0] > few.shape[0] > 200 and many.shape[1] == few.shape[1]
    for colour in ((31, 119, 180), (255, 127, 14)):  # both learners drawn
        assert (np.abs(few - colour).sum(axis=2) < 40).sum() > 30, colour
