"""``davis-ag stats``: Table 3 of the paper for any dataset, and its fruit statistics.

Works on what we generate and on the original download alike: scenes and images come from the
folders and annotations.json; fruit per plant and visible fractions from our scene.json where a
scene has one; boxes per view from the annotations; the OER of every box from the masks.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict
from typing import Any

import numpy as np

from davis_ag.data.reader import Dataset, Scene
from davis_ag.errors import UserError
from davis_ag.figures.scene_numbers import box_oers, visible_fractions
from davis_ag.scene.specs import CROPS, PAPER_TABLE3, SCENARIOS, parse_group_name

#: Where the OER distribution is summarised (section V-D starts episodes below 0.4).
OER_EDGES = np.linspace(0.0, 1.0, 11)


def _summary(values: np.ndarray | Sequence[float]) -> dict[str, Any] | None:
    """Count, mean, min, quartiles and max of some values; ``None`` when there are none."""
    data = np.asarray(values, dtype=float)
    if data.size == 0:
        return None
    q = np.quantile(data, [0.0, 0.25, 0.5, 0.75, 1.0])
    return {
        "n": int(data.size),
        "mean": float(data.mean()),
        "min": float(q[0]),
        "q1": float(q[1]),
        "median": float(q[2]),
        "q3": float(q[3]),
        "max": float(q[4]),
    }


def table3(dataset: Dataset) -> dict[str, Any]:
    """Scenes and images per scenario and crop, as the paper's Table 3.

    Args:
        dataset: The dataset.

    Returns:
        ``{"groups": {"Single-Strawberry": {"scenario", "crop", "scenes", "images",
        "images_per_scene": [min, max], "paper": {"scenes", "images"}}}, "total":
        {"scenes", "images"}}``. Folders whose name is no DAVIS-Ag group are counted under
        their own name with ``scenario`` and ``crop`` null.
    """
    groups: dict[str, Any] = {}
    for scene in dataset.scenes:
        entry = groups.setdefault(
            scene.group, {"scenario": scene.scenario, "crop": scene.crop, "scenes": 0, "images": 0, "per_scene": []}
        )
        entry["scenes"] += 1
        entry["images"] += len(scene.views)
        entry["per_scene"].append(len(scene.views))
    for entry in groups.values():
        per_scene = entry.pop("per_scene")
        entry["images_per_scene"] = [min(per_scene), max(per_scene)]
        paper = PAPER_TABLE3.get((entry["scenario"], entry["crop"]))
        entry["paper"] = {"scenes": paper[0], "images": paper[1]} if paper else None
    return {
        "groups": groups,
        "total": {
            "scenes": sum(g["scenes"] for g in groups.values()),
            "images": sum(g["images"] for g in groups.values()),
        },
    }


def fruit_statistics(dataset: Dataset, with_oer: bool = True) -> dict[str, Any]:
    """Fruit statistics per group: fruit per plant, boxes per view, OER, visible fraction.

    Args:
        dataset: The dataset.
        with_oer: Read every mask for the OER distribution (the slow part on a large dataset).

    Returns:
        Per group name: ``fruit_per_plant`` (scene.json; ``None`` without it),
        ``fruit_per_scene_boxed`` (distinct ids boxed in any view), ``boxes_per_view``,
        ``oer`` (summary plus ``histogram``: counts over :data:`OER_EDGES`, and
        ``below_0.4``: the share of boxes an episode may start on), ``masks_missing`` (boxes
        whose view had no mask) and ``visible_fraction`` (scene.json; ``None`` without it).
    """
    by_group: dict[str, list[Scene]] = {}
    for scene in dataset.scenes:
        by_group.setdefault(scene.group, []).append(scene)
    out: dict[str, Any] = {}
    for group, scenes in by_group.items():
        per_plant = [
            p.fruit_count
            for s in scenes
            for p in (s.metadata.plants if s.metadata else [])
            if p.fruit_count is not None
        ]
        boxed = [len({b.fruit_id for v in s.views.values() for b in v.boxes}) for s in scenes]
        per_view = [len(v.boxes) for s in scenes for v in s.views.values()]
        entry: dict[str, Any] = {
            "fruit_per_plant": _summary(per_plant),
            "fruit_per_scene_boxed": _summary(boxed),
            "boxes_per_view": _summary(per_view),
            "visible_fraction": _summary(visible_fractions(scenes)),
        }
        if with_oer:
            oers, missing = box_oers(scenes)
            summary = _summary(oers)
            if summary is not None:
                summary["histogram"] = {
                    "edges": OER_EDGES.tolist(),
                    "counts": np.histogram(oers, OER_EDGES)[0].tolist(),
                }
                summary["below_0.4"] = float(np.mean(oers < 0.4))
            entry["oer"] = summary
            entry["masks_missing"] = missing
        out[group] = entry
    return out


def refused_move_statistics(dataset: Dataset) -> dict[str, Any]:
    """Per group, the share of moves TVM-v0 refuses from its episode starts (:mod:`davis_ag.benchmark.moves`).

    Reads (and if needed builds) the benchmark's observation caches. A group without an
    eligible start has ``starts`` 0 and ``share`` None; one whose benchmark cache cannot be built
    (a download without masks) has ``share`` None and ``skipped``, the reason.
    """
    from davis_ag.benchmark.cache import load_scene_cache
    from davis_ag.benchmark.moves import refused_moves_of_scenes

    by_group: dict[str, list[Scene]] = {}
    for scene in dataset.scenes:
        by_group.setdefault(scene.group, []).append(scene)
    out: dict[str, Any] = {}
    for group, scenes in by_group.items():
        parsed = parse_group_name(group)
        if parsed is None:
            continue
        try:
            caches = [load_scene_cache(s, dataset.root) for s in scenes]
        except UserError as error:  # no masks, no OER: nothing to start from
            out[group] = {"share": None, "skipped": str(error)}
            continue
        counts = refused_moves_of_scenes(scenes, caches, parsed[0].name)
        out[group] = {**asdict(counts), "share": None if not counts.moves else counts.share}
    return out


def dataset_statistics(dataset: Dataset, with_oer: bool = True) -> dict[str, Any]:
    """Everything ``davis-ag stats`` reports, JSON-ready.

    Args:
        dataset: The dataset.
        with_oer: Include the OER distribution (reads every mask) and the refused-move share
            (reads the benchmark's caches).

    Returns:
        ``{"dataset": root, "table3": ..., "fruit": ..., "refused_moves": ...}``.
    """
    stats = {"dataset": str(dataset.root), "table3": table3(dataset), "fruit": fruit_statistics(dataset, with_oer)}
    if with_oer:
        stats["refused_moves"] = refused_move_statistics(dataset)
    return stats


def _grid(rows: list[list[str]]) -> list[str]:
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    return [
        "  ".join(c.rjust(w) if i else c.ljust(w) for i, (c, w) in enumerate(zip(r, widths))).rstrip() for r in rows
    ]


def _stat(summary: dict[str, Any] | None, fmt: str = "{:.1f}") -> str:
    if not summary:
        return "-"
    return f"{fmt.format(summary['mean'])} [{fmt.format(summary['min'])}-{fmt.format(summary['max'])}]"


def format_statistics(stats: dict[str, Any]) -> str:
    """Plain-text tables: Table 3 (ours beside the paper's) and the fruit statistics.

    Args:
        stats: What :func:`dataset_statistics` returned.

    Returns:
        The text, lines joined by newlines.
    """
    order = [f"{SCENARIOS[s].title}-{CROPS[c].title}" for c in CROPS for s in SCENARIOS]
    groups = stats["table3"]["groups"]
    names = [g for g in order if g in groups] + sorted(g for g in groups if g not in order)
    rows = [["Table 3", *names]]
    rows.append(["scenes", *[f"{groups[g]['scenes']:,}" for g in names]])
    rows.append(["images", *[f"{groups[g]['images']:,}" for g in names]])
    rows.append(
        [
            "images/scene",
            *[
                "{}-{}".format(*groups[g]["images_per_scene"])
                if len(set(groups[g]["images_per_scene"])) > 1
                else str(groups[g]["images_per_scene"][0])
                for g in names
            ],
        ]
    )
    rows.append(["paper scenes", *[f"{groups[g]['paper']['scenes']:,}" if groups[g]["paper"] else "-" for g in names]])
    rows.append(["paper images", *[f"{groups[g]['paper']['images']:,}" if groups[g]["paper"] else "-" for g in names]])
    total = stats["table3"]["total"]
    lines = _grid(rows)
    lines.append(f"total: {total['scenes']:,} scenes, {total['images']:,} images (paper: 632 scenes, 502,542 images)")
    fruit = stats["fruit"]
    rows = [["fruit: mean [min-max]", *names]]
    rows.append(["fruit per plant", *[_stat(fruit[g]["fruit_per_plant"]) for g in names]])
    rows.append(["fruit boxed per scene", *[_stat(fruit[g]["fruit_per_scene_boxed"]) for g in names]])
    rows.append(["boxes per view", *[_stat(fruit[g]["boxes_per_view"]) for g in names]])
    if any("oer" in fruit[g] for g in names):
        rows.append(["OER per box", *[_stat(fruit[g].get("oer"), "{:.2f}") for g in names]])
        rows.append(
            [
                "boxes with OER < 0.4",
                *[f"{fruit[g]['oer']['below_0.4']:.1%}" if fruit[g].get("oer") else "-" for g in names],
            ]
        )
    rows.append(["visible fraction", *[_stat(fruit[g]["visible_fraction"], "{:.2f}") for g in names]])
    refused = stats.get("refused_moves", {})
    if refused:
        rows.append(
            [
                "moves refused from starts",
                *[
                    f"{refused[g]['share']:.1%} of {refused[g]['moves']:,}"
                    if refused.get(g, {}).get("share") is not None
                    else "-"
                    for g in names
                ],
            ]
        )
    lines += ["", *_grid(rows)]
    missing = sum(fruit[g].get("masks_missing", 0) for g in names)
    if missing:
        lines.append(f"{missing} boxes had no mask and no OER")
    return "\n".join(lines)
