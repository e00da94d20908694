"""The benchmark's figures: the OER distribution over every fruit instance (the paper's Fig. 4b),
the frequency of each action per evaluated policy (Fig. 4c) and the actions chosen episode by
episode (Fig. 5), the last two from ``davis-ag evaluate``'s results JSON.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from davis_ag.data.reader import Scene
from davis_ag.errors import UserError
from davis_ag.figures.canvas import FORMATS, Plotted, new_figure, save_formats
from davis_ag.figures.scene_numbers import box_oers
from davis_ag.scene.specs import MP_ACTIONS, SP_ACTIONS

#: Section V-D: episodes start on a target below this OER.
START_OER = 0.4
#: Fig. 4b's bins: twenty of 0.05 over [0, 1].
OER_BINS = np.linspace(0.0, 1.0, 21)
#: Fig. 5 shows this many episodes.
EPISODES_SHOWN = 100


def plot_oer(scenes: list[Scene], out: str | Path, formats: tuple[str, ...] = FORMATS, title: str = "") -> Plotted:
    """Fig. 4b: histogram of the OER (eq. 1) of every box of the scenes, from their masks.

    Args:
        scenes: The scenes.
        out: Output path without suffix.
        formats: File formats to write.
        title: Figure title (default: how many boxes and the share an episode may start on).

    Returns:
        The paths and ``{"boxes", "edges", "counts", "below_start", "masks_missing"}``.

    Raises:
        UserError: when no box has a mask.
    """
    oers, missing = box_oers(scenes)
    if oers.size == 0:
        raise UserError(
            f"{scenes[0].path.parent.parent if scenes else 'dataset'}: no box with a "
            "mask (images/NNNN_seg.png): the OER needs the instance masks"
        )
    counts, edges = np.histogram(oers, bins=OER_BINS)
    below = float(np.mean(oers < START_OER))
    figure = new_figure(5.0, 3.3)
    ax = figure.add_subplot(1, 1, 1)
    ax.bar((edges[:-1] + edges[1:]) / 2, counts, width=np.diff(edges) * 0.92, color="tab:green")
    ax.axvline(START_OER, color="tab:red", linestyle="--", label=f"episode start: OER < {START_OER}")
    ax.set_xlabel("object exposure rate (OER)")
    ax.set_ylabel("fruit instances (boxes)")
    ax.set_xlim(0, 1)
    ax.set_title(title or f"{len(oers)} boxes in {len(scenes)} scene(s), {below:.1%} below {START_OER}", fontsize=9)
    ax.legend(fontsize=8)
    figure.tight_layout()
    paths = save_formats(figure, out, formats)
    return Plotted(
        paths,
        {
            "boxes": len(oers),
            "edges": edges.tolist(),
            "counts": counts.tolist(),
            "below_start": below,
            "masks_missing": missing,
        },
    )


def action_names(results: dict[str, Any]) -> list[str]:
    """The action names of a results file by index: its protocol's, else the scenario's."""
    protocol = results.get("protocol") or {}
    names = protocol.get("actions")
    if isinstance(names, list) and names:
        return [str(n) for n in names]
    moves = MP_ACTIONS if protocol.get("scenario") in ("mp", "row") else SP_ACTIONS
    return [*moves, "done"]


def episode_records(results: dict[str, Any], policy: str, source: str) -> list[dict[str, Any]]:
    episodes = results["policies"][policy].get("episodes")
    if not isinstance(episodes, list) or not episodes:
        raise UserError(
            f"{source}: policy {policy} has no per-episode records; rerun `davis-ag evaluate`, which now writes them"
        )
    return episodes


def policy_names(results: dict[str, Any], source: str, wanted: list[str] | None = None) -> list[str]:
    """The policies of a results file, or the ``wanted`` ones after checking they are there.

    Raises:
        UserError: for a file without policies or a policy it does not hold.
    """
    known = list(results.get("policies") or {})
    if not known:
        raise UserError(f"{source}: holds no policies; give the JSON `davis-ag evaluate --out` wrote")
    for name in wanted or []:
        if name not in known:
            raise UserError(f"{source}: no policy {name!r} (it has {', '.join(known)})")
    return list(wanted) if wanted else known


def action_frequencies(results: dict[str, Any], source: str, policies: list[str] | None = None) -> dict[str, list[int]]:
    """Times each action was chosen per policy, in action-index order.

    From the per-episode records where present, else from ``action_counts``.

    Raises:
        UserError: when a policy has neither (results written before either existed).
    """
    names = action_names(results)
    out: dict[str, list[int]] = {}
    for policy in policy_names(results, source, policies):
        summary = results["policies"][policy]
        if isinstance(summary.get("episodes"), list):
            flat = [a for e in summary["episodes"] for a in e["actions"]]
            out[policy] = np.bincount(flat, minlength=len(names)).astype(int).tolist()
        elif isinstance(summary.get("action_counts"), dict):
            out[policy] = [int(summary["action_counts"].get(n, 0)) for n in names]
        else:
            raise UserError(f"{source}: policy {policy} records no actions; rerun `davis-ag evaluate`")
    return out


def plot_actions(
    results: dict[str, Any],
    out: str | Path,
    formats: tuple[str, ...] = FORMATS,
    policies: list[str] | None = None,
    choices_of: str | None = None,
    episodes_shown: int = EPISODES_SHOWN,
    source: str = "results",
) -> Plotted:
    """Fig. 4c (share of each action per policy) beside Fig. 5 (one policy's choices per episode).

    Fig. 5 is a map: one column per episode (the first ``episodes_shown`` of session 0 onwards),
    one row per step, coloured by the action taken; steps after the episode ended stay blank.

    Args:
        results: ``davis-ag evaluate``'s results.
        out: Output path without suffix.
        formats: File formats to write.
        policies: Policies of Fig. 4c (default: all).
        choices_of: The policy of Fig. 5 (default: A2C where present, else the first).
        episodes_shown: Episodes in Fig. 5.
        source: The results file's name, for messages.

    Returns:
        The paths and ``{"actions", "counts": {policy: [...]}, "shares": {...}, "choices_of",
        "choices": [[action index per step] per episode]}``.

    Raises:
        UserError: for results without action records or an unknown policy.
    """
    names = action_names(results)
    counts = action_frequencies(results, source, policies)
    known = policy_names(results, source)
    choices_of = choices_of or ("A2C" if "A2C" in known else known[0])
    policy_names(results, source, [choices_of])
    chosen = [list(e["actions"]) for e in episode_records(results, choices_of, source)[:episodes_shown]]
    steps = max((len(c) for c in chosen), default=1)
    grid = np.full((steps, len(chosen)), np.nan)
    for column, actions in enumerate(chosen):
        grid[: len(actions), column] = actions

    from matplotlib import colormaps
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    # Set1 (9 colours, one per MP action) so that actions never share the policies' colours of (a).
    palette = [colormaps["Set1"](i % 9) for i in range(len(names))]
    figure = new_figure(13.0, 3.8)
    left = figure.add_subplot(1, 2, 1)
    width = 0.8 / len(counts)
    shares = {}
    for k, (policy, values) in enumerate(counts.items()):
        total = max(sum(values), 1)
        shares[policy] = [v / total for v in values]
        left.bar(
            np.arange(len(names)) - 0.4 + width * (k + 0.5), shares[policy], width=width, label=policy, color=f"C{k}"
        )
    left.set_xticks(range(len(names)), [f"{i}\n{n}" for i, n in enumerate(names)], fontsize=7)
    left.set_ylabel("share of actions")
    left.set_title("(a) action frequencies", fontsize=9)
    left.legend(fontsize=7)
    right = figure.add_subplot(1, 2, 2)
    cmap = ListedColormap(palette).with_extremes(bad="white")
    right.imshow(
        np.ma.masked_invalid(grid),
        aspect="auto",
        interpolation="nearest",
        cmap=cmap,
        norm=BoundaryNorm(np.arange(len(names) + 1) - 0.5, len(names)),
        extent=(0.5, len(chosen) + 0.5, steps + 0.5, 0.5),
    )
    right.set_yticks(range(1, steps + 1))
    right.set_xlabel("episode")
    right.set_ylabel("step t")
    right.set_title(f"(b) {choices_of}: actions in {len(chosen)} episodes", fontsize=9)
    right.legend(
        handles=[Patch(color=palette[i], label=f"{i} {n}") for i, n in enumerate(names)],
        fontsize=7,
        loc="center left",
        bbox_to_anchor=(1.01, 0.5),
        frameon=False,
    )
    protocol = results.get("protocol") or {}
    figure.suptitle(
        f"{str(protocol.get('scenario', '')).upper()} {protocol.get('split', '')}: "
        f"{protocol.get('sessions', '?')} x {protocol.get('episodes', '?')} episodes",
        fontsize=9,
    )
    figure.tight_layout()
    paths = save_formats(figure, out, formats)
    return Plotted(
        paths, {"actions": names, "counts": counts, "shares": shares, "choices_of": choices_of, "choices": chosen}
    )
