"""Fig. 4a: episodic reward while A2C trains, from the learning curve in a model's training record
(``NAME.training.json``, written by :func:`davis_ag.benchmark.training.train_a2c`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from davis_ag.errors import UserError
from davis_ag.figures.canvas import FORMATS, Plotted, new_figure, save_formats

#: Points (of 1K steps each) in the rolling average drawn over the raw curve, as the paper's
#: "some level of rolling average applied for clarity".
ROLLING_POINTS = 10


def rolling_mean(values: np.ndarray, weights: np.ndarray, window: int) -> np.ndarray:
    """Episode-weighted mean over the last ``window`` points (fewer at the start)."""
    kernel = np.ones(window)
    sums = np.convolve(values * weights, kernel)[: len(values)]
    counts = np.convolve(weights, kernel)[: len(values)]
    return sums / np.maximum(counts, 1e-12)


def plot_learning_curve(
    records: dict[str, dict[str, Any]],
    out: str | Path,
    formats: tuple[str, ...] = FORMATS,
    window: int = ROLLING_POINTS,
    references: dict[str, float] | None = None,
) -> Plotted:
    """Fig. 4a: mean episodic reward per 1K training steps, with a rolling average, per model.

    Args:
        records: Label (e.g. ``sp-strawberry``) to a training record with a ``curve``.
        out: Output path without suffix.
        formats: File formats to write.
        window: Points in the rolling average.
        references: What a trivial policy scores on the train split, drawn across the snapshot
            panel as dashed lines so a learner below them reads as one that did not learn
            (e.g. ``{"sp-strawberry: best fixed action (always backward), exact": 0.434}``).

    Records that kept their best train-split snapshot (``selection``) get a second panel: each
    snapshot's train-split OER_tau against its step, the kept one ringed.

    Returns:
        The paths and ``{label: {"steps": [...], "reward": [...], "smoothed": [...]}}`` (with
        ``"scored_steps"``, ``"scored_oer_tau"`` and ``"kept_step"`` for a record with a selection).

    Raises:
        UserError: when no record has a learning curve (models trained before curves were kept).
    """
    curves = {label: r["curve"] for label, r in records.items() if r.get("curve")}
    if not curves:
        raise UserError(
            "no training record holds a learning curve: retrain with this version of "
            "`davis-ag train`, which keeps one in NAME.training.json"
        )
    selections = {
        label: records[label]["selection"] for label in curves if (records[label].get("selection") or {}).get("scores")
    }
    figure = new_figure(6.0, 6.2 if selections else 3.6)
    axes = figure.add_subplot(2, 1, 1) if selections else figure.add_subplot(1, 1, 1)
    data: dict[str, dict[str, Any]] = {}
    for k, (label, curve) in enumerate(curves.items()):
        steps = np.array([p["step"] for p in curve], dtype=float)
        reward = np.array([p["reward"] for p in curve], dtype=float)
        episodes = np.array([p["episodes"] for p in curve], dtype=float)
        smoothed = rolling_mean(reward, episodes, window)
        axes.plot(steps / 1000, reward, color=f"C{k}", alpha=0.25, linewidth=0.8)
        axes.plot(steps / 1000, smoothed, color=f"C{k}", linewidth=1.8, label=label)
        data[label] = {"steps": steps.astype(int).tolist(), "reward": reward.tolist(), "smoothed": smoothed.tolist()}
    axes.set_xlabel("training steps (thousands)")
    axes.set_ylabel("episodic reward")
    learners = sorted({str(records[label].get("algorithm", "A2C")) for label in curves})
    name = f"{learners[0]} learning curve" if len(learners) == 1 else "learning curves"
    axes.set_title(f"{name}: mean reward per 1K steps (faint), rolling mean of {window} (bold)", fontsize=8)
    axes.legend(fontsize=8)
    if selections:
        lower = figure.add_subplot(2, 1, 2, sharex=axes)
        for k, label in enumerate(curves):
            if label not in selections:
                continue
            scores = sorted(selections[label]["scores"], key=lambda e: e["step"])
            steps = np.array([e["step"] for e in scores], dtype=float)
            oer = np.array([e["oer_tau"] for e in scores], dtype=float)
            kept = selections[label].get("kept_step")
            lower.plot(steps / 1000, oer, color=f"C{k}", marker="o", markersize=3, linewidth=1, label=label)
            if kept is not None and kept in steps:
                lower.plot(
                    kept / 1000,
                    oer[list(steps).index(kept)],
                    marker="o",
                    markersize=11,
                    markerfacecolor="none",
                    markeredgecolor="black",
                    linestyle="none",
                )
            data[label].update(scored_steps=steps.astype(int).tolist(), scored_oer_tau=oer.tolist(), kept_step=kept)
        for k, (text, value) in enumerate((references or {}).items()):
            lower.axhline(value, color="black", linestyle=("--", ":", "-.")[k % 3], linewidth=1, label=text)
        played = {(sel.get("episodes", 200), sel.get("play", "sampled")) for sel in selections.values()}
        how = "{} {} episodes".format(*next(iter(played))) if len(played) == 1 else "each learner's episodes"
        lower.set_xlabel("training steps (thousands)")
        lower.set_ylabel("train-split OER_tau")
        lower.set_title(f"each snapshot on the train split ({how}); ringed: the one kept", fontsize=8)
        # Under the panel: inside it, the legend would hide the snapshots it names.
        lower.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.28), ncol=2, frameon=False)
    figure.tight_layout()
    return Plotted(save_formats(figure, out, formats), data)
