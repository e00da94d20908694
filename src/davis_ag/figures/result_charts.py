"""Charts of benchmark results and training runs: the Table 4 bar chart of an evaluation and the
training curve of a continuous-pose PPO run, each saved atomically as PNG.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from davis_ag.atomic_files import save_figure_atomic
from davis_ag.benchmark.evaluation import METRICS


def plot_results(results: dict[str, Any], path: str | os.PathLike[str]) -> Path:
    """Bar chart of the three Table 4 metrics per policy, with the std over sessions as error
    bars, saved as PNG.

    Args:
        results: What :func:`davis_ag.benchmark.evaluation.evaluate_policies` returned, as JSON.
        path: The PNG to write.

    Returns:
        ``path``.
    """
    import matplotlib

    matplotlib.use("Agg")  # files only: no display on servers
    import matplotlib.pyplot as plt

    policies = results["policies"]
    names = list(policies)
    fig, axes = plt.subplots(1, len(METRICS), figsize=(4 * len(METRICS), 3.2))
    for ax, (key, title) in zip(axes, METRICS.items()):
        means = [policies[n][key]["mean"] for n in names]
        stds = [policies[n][key]["std"] for n in names]
        ax.bar(names, means, yerr=stds, capsize=4, color=[f"C{i}" for i in range(len(names))])
        ax.set_title(title)
        ax.tick_params(axis="x", labelrotation=30)
    protocol = results["protocol"]
    # What the bars rest on: the split's scenes and eligible starts (the grid's; drawn live otherwise).
    starts = f", {protocol['starts']} eligible starts" if protocol.get("starts") is not None else ""
    fig.suptitle(
        f"{protocol['scenario'].upper()} {protocol['split']}: {len(protocol.get('scenes', []))} scene(s)"
        f"{starts}, {protocol['sessions']} x {protocol['episodes']} episodes"
    )
    fig.tight_layout()
    try:
        return save_figure_atomic(fig, path, dpi=120)
    finally:
        plt.close(fig)


def plot_training_curve(records: list[dict], path: str | os.PathLike[str], title: str, window: int = 50) -> Path:
    """Reward and final OER per episode against environment steps, with a moving mean, as PNG.

    Args:
        records: What :func:`train_continuous` returned.
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
