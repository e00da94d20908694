"""Charts of benchmark results and training runs: the Table 4 bar chart of an evaluation, each
learner's gap to the Best fixed action scene by scene, a ladder of groups from hardest to
easiest (the crops run's), and the training curve of a continuous-pose PPO run, each saved
atomically as PNG.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from davis_ag.atomic_files import save_figure_atomic
from davis_ag.benchmark.results import EvaluationResults, as_results
from davis_ag.benchmark.results_table import METRICS


def plot_results(results: EvaluationResults | dict[str, Any], path: str | os.PathLike[str]) -> Path:
    """Bar chart of the three Table 4 metrics per policy, with the std over sessions as error
    bars, saved as PNG.

    Args:
        results: What :func:`davis_ag.benchmark.evaluation.evaluate_policies` returned (or its JSON).
        path: The PNG to write.

    Returns:
        ``path``.
    """
    import matplotlib

    matplotlib.use("Agg")  # files only: no display on servers
    import matplotlib.pyplot as plt

    results = as_results(results)
    policies = results.policies
    names = list(policies)
    fig, axes = plt.subplots(1, len(METRICS), figsize=(4 * len(METRICS), 3.2))
    for ax, (key, title) in zip(axes, METRICS.items()):
        means = [getattr(policies[n], key).mean for n in names]
        stds = [getattr(policies[n], key).std for n in names]
        ax.bar(names, means, yerr=stds, capsize=4, color=[f"C{i}" for i in range(len(names))])
        ax.set_title(title)
        # Anchored at their right end, long names ("A2C (deterministic)") end under their own bar.
        plt.setp(ax.get_xticklabels(), rotation=30, ha="right", rotation_mode="anchor")
    protocol = results.protocol
    # What the bars rest on: the split's scenes and eligible starts (the grid's; drawn live otherwise).
    starts = f", {protocol.starts} eligible starts" if protocol.starts is not None else ""
    fig.suptitle(
        f"{protocol.scenario.upper()} {protocol.split}: {len(protocol.scenes)} scene(s)"
        f"{starts}, {protocol.sessions} x {protocol.episodes} episodes"
    )
    fig.tight_layout()
    try:
        return save_figure_atomic(fig, path, dpi=120)
    finally:
        plt.close(fig)


def plot_training_curve(records: list[dict], path: str | os.PathLike[str], title: str, window: int = 50) -> Path:
    """Reward and final OER per episode against environment steps, with a moving mean, as PNG.

    Args:
        records: What :func:`davis_ag.live.training.train_continuous` returned.
        path: The PNG.
        title: The figure's title.
        window: Episodes in the moving mean.

    Returns:
        ``path``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    steps = np.array([r["timestep"] for r in records])
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.2))
    for ax, key, label in ((axes[0], "reward", "episode reward"), (axes[1], "gain", "OER_tau - OER_0")):
        values = np.array([r["reward"] if key == "reward" else r["oer_tau"] - r["oer_0"] for r in records])
        ax.plot(steps, values, ".", ms=2, alpha=0.3, color="C0")
        if len(values) >= window:
            mean = np.convolve(values, np.ones(window) / window, mode="valid")
            ax.plot(steps[window - 1 :], mean, color="C1", label=f"mean of {window} episodes")
            ax.legend(loc="upper left", fontsize=8)
        ax.set_xlabel("environment steps")
        ax.set_title(label)
    fig.suptitle(title)
    fig.tight_layout()
    try:
        return save_figure_atomic(fig, path, dpi=110)
    finally:
        plt.close(fig)


def plot_scene_gaps(gaps: dict[str, dict[str, Any]], path: str | os.PathLike[str], title: str) -> Path:
    """Each learner's gap to the Best fixed action on each test scene, as PNG: a dot per scene
    (its area by the scene's episodes), the mean gap as a line, and the intervals over episodes
    (dark band) and over scenes (light band) around it, beside zero.

    Args:
        gaps: Per learner (``A2C``, ``PPO``), its paired gap as JSON
            (:func:`davis_ag.benchmark.paired.a2c_against_best_fixed`).
        path: The PNG to write.
        title: The chart's title (the scenario and split).

    Returns:
        ``path``.
    """
    import matplotlib

    matplotlib.use("Agg")  # files only: no display on servers
    import matplotlib.pyplot as plt

    scenes = sorted({s["scene"] for gap in gaps.values() for s in gap["per_scene"]})
    x = {scene: i for i, scene in enumerate(scenes)}
    width = max(6.0, 0.32 * len(scenes) + 2.5)
    # Each learner's two legend entries take about 4.8 inches at this size: on a figure of few
    # scenes they go two to a row, so none is cut at the figure's edge.
    columns = 2 * len(gaps) if width >= 4.8 * len(gaps) else 2
    rows = -(-2 * len(gaps) // columns)
    fig, ax = plt.subplots(figsize=(width, 3.8 + 0.2 * (rows - 1)))
    ax.axhline(0.0, color="black", linewidth=0.8)
    spread = 0.18 * (len(gaps) > 1)  # learners side by side within a scene's slot
    for i, (learner, gap) in enumerate(gaps.items()):
        colour = f"C{i}"
        offset = spread * (i - (len(gaps) - 1) / 2)
        per_scene = gap["per_scene"]
        ax.scatter(
            [x[s["scene"]] + offset for s in per_scene],
            [s["gap"] for s in per_scene],
            s=[12 + 2 * s["episodes"] for s in per_scene],
            color=colour,
            alpha=0.75,
            label=f"{learner}: each test scene (area: episodes)",
        )
        ends = (-0.5, len(scenes) - 0.5)
        if gap.get("scene_low") is not None:
            ax.fill_between(ends, gap["scene_low"], gap["scene_high"], color=colour, alpha=0.12, linewidth=0)
        ax.fill_between(ends, gap["low"], gap["high"], color=colour, alpha=0.3, linewidth=0)
        ax.plot(ends, [gap["gap"]] * 2, color=colour, linewidth=1.5, label=f"{learner}: mean {gap['gap']:+.3f}")
    ax.set_xlim(-0.5, len(scenes) - 0.5)
    ax.set_xticks(range(len(scenes)))
    ax.set_xticklabels([s.split("/")[-1] for s in scenes], fontsize=7)
    ax.set_xlabel(f"test scene ({scenes[0].split('/')[0]}/…)" if scenes else "test scene")
    ax.set_ylabel("OER_tau minus Best fixed action")
    ax.set_title(f"{title}: bands, 95 % intervals over episodes (dark) and over scenes (light)", fontsize=9)
    fig.legend(fontsize=7, loc="lower center", ncol=columns, frameon=False, markerscale=0.5)
    fig.tight_layout(rect=(0, 0.02 + 0.06 * rows, 1, 1))  # the legend's rows below the axes
    try:
        return save_figure_atomic(fig, path, dpi=120)
    finally:
        plt.close(fig)


def plot_ladder(rows: list[dict[str, Any]], path: str | os.PathLike[str], title: str) -> Path:
    """A ladder of groups (a crop in a scenario), hardest at the top, as PNG: each group's line runs
    from its start OER (OER_0) to the exact Oracle, the shaded part is the headroom above the Best
    fixed action, and each learner is a dot with its paired interval to the Best fixed action.

    Args:
        rows: Per group, top first: ``label``, ``oer_0``, ``rand``, ``best_fixed``, ``oracle``
            (None where not played) and ``learners``: per learner its ``mean`` OER_tau and, where
            paired, ``low`` and ``high``, the interval of its gap to the Best fixed action.
        path: The PNG to write.
        title: The chart's title.

    Returns:
        ``path``.
    """
    import matplotlib

    matplotlib.use("Agg")  # files only: no display on servers
    import matplotlib.pyplot as plt

    learners = list(dict.fromkeys(name for row in rows for name in row["learners"]))
    fig, ax = plt.subplots(figsize=(8.0, 2.0 + 0.42 * len(rows)))
    marks = (
        ("oer_0", "x", "grey", "OER_0 (the start)"),
        ("rand", "o", "none", "Rand"),
        ("best_fixed", "|", "black", "Best fixed action"),
        ("oracle", "D", "black", "Oracle (exact)"),
    )
    labelled: set[str] = set()

    def once(name: str) -> str:
        """The legend's label the first time a mark is drawn, none after."""
        first = name not in labelled
        labelled.add(name)
        return name if first else "_"

    for y, row in enumerate(rows):
        present = [row[key] for key, *_ in marks if row.get(key) is not None]
        if present:
            ax.plot([min(present), max(present)], [y, y], color="lightgrey", linewidth=1, zorder=1)
        if row.get("best_fixed") is not None and row.get("oracle") is not None:
            ax.fill_betweenx(
                [y - 0.3, y + 0.3], row["best_fixed"], row["oracle"], color="0.9", zorder=0, label=once("headroom")
            )
        for key, marker, face, name in marks:
            if row.get(key) is not None:
                size = 14 if marker == "|" else 6
                ax.plot(row[key], y, marker, ms=size, mfc=face, mec="black", color="black", label=once(name), zorder=3)
        for i, learner in enumerate(learners):
            score = row["learners"].get(learner)
            if score is None:
                continue
            dy = 0.16 * (i - (len(learners) - 1) / 2)
            colour = f"C{i}"
            if score.get("low") is not None and row.get("best_fixed") is not None:
                ax.plot(
                    [row["best_fixed"] + score["low"], row["best_fixed"] + score["high"]],
                    [y + dy] * 2,
                    color=colour,
                    linewidth=2.5,
                    zorder=4,
                )
            ax.plot(score["mean"], y + dy, "o", ms=5, color=colour, label=once(learner), zorder=5)
    ax.set_yticks(range(len(rows)))
    ax.set_yticklabels([row["label"] for row in rows], fontsize=8)
    ax.set_ylim(len(rows) - 0.5, -0.5)  # the first row at the top
    ax.set_xlim(0.0, 1.0)
    ax.set_xlabel("OER_tau on the test split; a learner's bar: Best fixed action + its gap's 95 % interval", fontsize=8)
    ax.grid(axis="x", color="0.92")
    ax.set_title(title, fontsize=9)
    fig.legend(fontsize=7, loc="lower center", ncol=4, frameon=False, markerscale=0.7)
    legend_rows = -(-len(labelled) // 4)
    fig.tight_layout(rect=(0, (0.02 + 0.16 * legend_rows) / fig.get_figheight(), 1, 1))  # the legend below
    try:
        return save_figure_atomic(fig, path, dpi=120)
    finally:
        plt.close(fig)
