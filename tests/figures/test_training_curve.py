"""Fig. 4a from a training record's learning curve."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from davis_ag.errors import UserError
from davis_ag.figures.training_curve import plot_learning_curve, rolling_mean


def test_rolling_mean_weights_points_by_their_episodes() -> None:
    values, weights = np.array([1.0, 0.0, 0.0, 4.0]), np.array([1.0, 3.0, 1.0, 1.0])
    # Window 2: (1*1)/1, (1*1+0*3)/4, (0*3+0*1)/4, (0*1+4*1)/2.
    assert rolling_mean(values, weights, 2) == pytest.approx([1.0, 0.25, 0.0, 2.0])


def test_learning_curve_png_and_numbers(tmp_path: Path) -> None:
    curve = [{"step": 1000 * (k + 1), "episodes": 300, "reward": 0.01 + 0.001 * k, "length": 2.9} for k in range(30)]
    plotted = plot_learning_curve(
        {"sp-strawberry": {"curve": curve}, "mp-vine": {}}, tmp_path / "curve", formats=("png",), window=5
    )
    assert plotted.paths == [tmp_path / "curve.png"] and plotted.paths[0].read_bytes()[:4] == b"\x89PNG"
    data = plotted.data["sp-strawberry"]
    assert data["steps"][-1] == 30_000 and data["smoothed"][-1] == pytest.approx(
        np.mean([0.01 + 0.001 * k for k in range(25, 30)])
    )
    assert "mp-vine" not in plotted.data  # a record without a curve draws nothing
    with pytest.raises(UserError, match="no training record holds a learning curve"):
        plot_learning_curve({"sp-strawberry": {}}, tmp_path / "none", formats=("png",))


def test_a_record_that_kept_its_best_snapshot_draws_the_scores(tmp_path: Path) -> None:
    curve = [{"step": 1000 * (k + 1), "episodes": 300, "reward": 0.02, "length": 3.0} for k in range(30)]
    scores = [{"step": 10_000, "oer_tau": 0.50}, {"step": 20_000, "oer_tau": 0.58}, {"step": 30_000, "oer_tau": 0.44}]
    selection = {"scores": scores, "kept_step": 20_000}
    plotted = plot_learning_curve(
        {"sp-strawberry": {"curve": curve, "selection": selection}}, tmp_path / "curve", formats=("png",)
    )
    data = plotted.data["sp-strawberry"]
    assert data["scored_steps"] == [10_000, 20_000, 30_000] and data["scored_oer_tau"] == [0.50, 0.58, 0.44]
    assert data["kept_step"] == 20_000
    from PIL import Image

    alone = plot_learning_curve({"sp-strawberry": {"curve": curve}}, tmp_path / "alone", formats=("png",))
    with Image.open(plotted.paths[0]) as two, Image.open(alone.paths[0]) as one:
        assert two.height > 1.4 * one.height  # a second panel under the curve


def test_a_trivial_policys_train_score_is_drawn_across_the_snapshots(tmp_path: Path) -> None:
    """The best fixed action's train-split score crosses the snapshot panel, so a learner below it
    reads as one that did not learn."""
    from PIL import Image

    curve = [{"step": 1000 * (k + 1), "episodes": 300, "reward": 0.02, "length": 3.0} for k in range(30)]
    scores = [{"step": 10_000, "oer_tau": 0.40}, {"step": 20_000, "oer_tau": 0.48}, {"step": 30_000, "oer_tau": 0.44}]
    record = {"curve": curve, "selection": {"scores": scores, "kept_step": 20_000}, "algorithm": "PPO"}
    plain = plot_learning_curve({"sp-strawberry": record}, tmp_path / "plain", formats=("png",))
    marked = plot_learning_curve(
        {"sp-strawberry": record},
        tmp_path / "marked",
        formats=("png",),
        references={"sp-strawberry: best fixed action (always backward), exact": 0.45},
    )
    with Image.open(plain.paths[0]) as a, Image.open(marked.paths[0]) as b:
        lower_a = np.asarray(a.convert("L"))[a.height // 2 :]
        lower_b = np.asarray(b.convert("L"))[b.height // 2 :]
        assert a.size == b.size
        # A dashed line spans the panel: many more dark pixels in the lower half.
        assert (lower_b < 100).sum() > (lower_a < 100).sum() + 200
        upper_a, upper_b = np.asarray(a.convert("L"))[: a.height // 2], np.asarray(b.convert("L"))[: b.height // 2]
        assert (upper_a == upper_b).all()  # the reward curve is untouched
