"""Section VI-A, Table 5: does pre-training on DAVIS-Ag help a detector on real images?

Stages (each resumable: a finished training run's ``done.json`` and a split's scores are kept;
the work folder records the settings, ``transfer-config.json``, and refuses a run of others):

1. export the DAVIS-Ag dataset to the ultralytics layout (its train split trains, its test split
   validates) and pre-train YOLOv5n on it (``pretrain`` budget);
2. for each of N random splits of the real set (the paper: three, 654 train / 159 test images),
   train YOLOv5n on the split's training images from scratch (Real-Only) and from the
   pre-trained weights (DAVIS-Ag -> Real), with the same budget, and score both on the split's
   test images: mAP@50 and mAP@50:95.

Writes ``OUT/transfer.json`` and, if asked, a Markdown table shaped like Table 5.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from davis_ag.atomic_files import write_json_atomic, write_text_atomic
from davis_ag.detection.real_sets import PAPER_TEST, PAPER_TRAIN, load_pool, split_sizes, write_split
from davis_ag.detection.yolo_export import export_yolo
from davis_ag.detection.yolo_training import FINEST_STRIDE, Budget, evaluate, median_box_side, train
from davis_ag.errors import UserError
from davis_ag.stage_timer import Timer

#: Table 5 of the paper (YOLOv5n, real strawberry set of Lemsalu et al. 2022), per split 1-3.
PAPER_TABLE5: dict[str, dict[str, list[float]]] = {
    "real_only": {"map50": [0.943, 0.888, 0.920], "map50_95": [0.619, 0.504, 0.505]},
    "transfer": {"map50": [0.945, 0.911, 0.936], "map50_95": [0.618, 0.511, 0.517]},
}
ARMS = (("real_only", "Real-Only"), ("transfer", "DAVIS-Ag -> Real"))


@dataclass(frozen=True)
class TransferConfig:
    """One run of the experiment.

    Attributes:
        pretrain: DAVIS-Ag dataset to pre-train on (root, group or scene folder).
        real: The real set: an ultralytics data YAML, a folder with images/ and labels/, or a COCO JSON.
        out: Work folder.
        real_images: Image folder for a COCO ``real`` (default: as its file names say).
        real_label: How the results name the real set (say "stand-in" when it is not real).
        splits: Random splits of the real set.
        train_size: Training images per split (the paper's 654).
        test_size: Test images per split (the paper's 159).
        seed: Split ``k`` (from 0) draws with ``seed + k``; training runs are seeded with it too.
        pretrain_budget: Pre-training budget.
        budget: Budget of every run on the real set, both arms alike.
    """

    pretrain: Path
    real: Path
    out: Path
    real_images: Path | None = None
    real_label: str = "real set"
    splits: int = 3
    train_size: int = PAPER_TRAIN
    test_size: int = PAPER_TEST
    seed: int = 0
    pretrain_budget: Budget = field(default_factory=Budget)
    budget: Budget = field(default_factory=Budget)


def _jsonable(config: TransferConfig) -> dict[str, Any]:
    data = asdict(config)
    return {k: str(v) if isinstance(v, Path) else v for k, v in data.items()}


#: The work folder's record of what its runs were made with.
WORK_RECORD = "transfer-config.json"


def _settings(config: dict[str, Any]) -> dict[str, Any]:
    """What a work folder's runs depend on, from a config as ``transfer.json`` records it: not the
    folder, the label, or where and how fast the runs train (``device``, data-loading ``workers``)."""
    kept = {k: v for k, v in config.items() if k not in ("out", "real_label")}
    for key in ("pretrain", "real"):
        kept[key] = str(Path(str(kept.get(key))).resolve())
    for key in ("budget", "pretrain_budget"):
        if isinstance(kept.get(key), dict):
            kept[key] = {k: v for k, v in kept[key].items() if k not in ("device", "workers")}
    return kept


def check_work_folder(config: TransferConfig) -> None:
    """Hold a work folder to one experiment: its finished runs and scores are reused, so a run of
    other settings (another pre-training set, real set, budget or seed) would report them as its own.

    A folder from before the record took its settings from its ``transfer.json``, when there is one.

    Raises:
        UserError: when the folder holds a run of other settings, or runs whose settings it never recorded.
    """
    wanted = _settings(_jsonable(config))
    record = config.out / WORK_RECORD
    made: Any = None
    for source in (record, config.out / "transfer.json"):
        try:
            found = json.loads(source.read_text()) if source.is_file() else None
        except (OSError, ValueError):
            found = None
        if isinstance(found, dict):
            made = found if source == record else _settings(found.get("config") or {})
            break
    if made is None:
        if any((config.out / name).exists() for name in ("runs", "split1")):
            raise UserError(
                f"{config.out} holds transfer runs of unrecorded settings: give another --out, or move it away"
            )
        write_json_atomic(record, wanted)
        return
    differ = [key for key in wanted if made.get(key) != wanted[key]]
    if differ:
        raise UserError(
            f"{config.out} holds a transfer run of other settings ({differ[0]}: {made.get(differ[0])} against "
            f"{wanted[differ[0]]}), whose runs and scores this one would reuse: give another --out, or move it away"
        )
    write_json_atomic(record, wanted)


def run_transfer(config: TransferConfig, say: Callable[[str], None] = print) -> dict[str, Any]:
    """Run the experiment (see the module docstring); returns what ``transfer.json`` holds.

    Raises:
        UserError: for unusable inputs (no DAVIS-Ag scene, an unreadable real set, too few images).
    """
    if config.splits < 1:
        raise UserError(f"--splits must be at least 1, got {config.splits}")
    started = time.perf_counter()
    timer = Timer()
    out = config.out
    pool = load_pool(config.real, config.real_images)
    n_train, n_test = split_sizes(len(pool.items), config.train_size, config.test_size)
    if (n_train, n_test) != (config.train_size, config.test_size):
        say(
            f"the real set has {len(pool.items)} images: splits of {n_train} train / {n_test} test "
            f"(the paper's {config.train_size}/{config.test_size} proportions)"
        )
    check_work_folder(config)  # once the inputs are known to be usable
    with timer.stage("export DAVIS-Ag"):
        say(f"exporting {config.pretrain} for pre-training")
        counts = export_yolo(config.pretrain, out / "pretrain-data", "detect")
    if not counts["train"]["images"]:
        raise UserError(f"{config.pretrain}: its train split has no view; give a dataset with train scenes")
    box_side = median_box_side(out / "pretrain-data", "train", config.pretrain_budget.imgsz)
    if box_side is not None and box_side < FINEST_STRIDE:
        say(
            f"note: the pre-training boxes are a median {box_side:.1f} px at --imgsz "
            f"{config.pretrain_budget.imgsz}, under YOLOv5n's {FINEST_STRIDE} px grid: few are learnt "
            "from; larger images or a larger --imgsz give the detector something to learn"
        )
    # A stage finished by an earlier sitting is reused: its time is the one that sitting measured.
    earlier = _earlier_wall_times(out / "transfer.json")
    if (out / "runs" / "pretrain" / "done.json").is_file():
        timer.notes["pre-train"] = "reused"
    with timer.stage("pre-train"):
        say("pre-training YOLOv5n on DAVIS-Ag")
        pretrained = train(
            out / "pretrain-data" / "data.yaml", out / "runs" / "pretrain", config.pretrain_budget, config.seed
        )
    results: dict[str, Any] = {
        "what": "Table 5 (section VI-A): YOLOv5n, Real-Only vs DAVIS-Ag -> Real",
        "real_set": config.real_label,
        "config": _jsonable(config),
        "pretrain_images": counts,
        "pretrain_median_box_px": None if box_side is None else round(box_side, 1),
        "real_images": len(pool.items),
        "split_sizes": {"train": n_train, "test": n_test},
        "splits": [],
        "paper_table5": PAPER_TABLE5,
    }
    for k in range(config.splits):
        seed = config.seed + k
        split_dir = out / f"split{k + 1}"
        scores_path = split_dir / "scores.json"
        reused_split = scores_path.is_file()
        if reused_split:
            timer.notes[f"split {k + 1}"] = "reused"
        with timer.stage(f"split {k + 1}"):  # a reused split too, so every stage keeps its place
            if reused_split:
                results["splits"].append(json.loads(scores_path.read_text()))
                continue
            data_yaml = write_split(pool, split_dir / "data", seed, n_train, n_test)
            scores: dict[str, Any] = {"split": k + 1, "seed": seed}
            for arm, title in ARMS:
                say(f"split {k + 1}/{config.splits}: {title}")
                weights = train(
                    data_yaml,
                    split_dir / "runs" / arm,
                    config.budget,
                    seed,
                    start=pretrained if arm == "transfer" else None,
                )
                scores[arm] = evaluate(weights, data_yaml, config.budget)
            write_json_atomic(scores_path, scores)
            results["splits"].append(scores)
    stages = {name: round(s, 1) for name, s in timer.stages.items()}
    reused = {name for name, note in timer.notes.items() if note == "reused"}
    if reused and all(name in earlier for name in reused):
        stages = {name: earlier[name] if name in reused else s for name, s in stages.items()}
        total = round(sum(stages.values()), 1)  # the sittings' work, not this sitting's wait
    else:
        total = round(time.perf_counter() - started, 1)
    results["wall_s"] = {**stages, "total": total}
    write_json_atomic(out / "transfer.json", results)
    return results


def _earlier_wall_times(path: Path) -> dict[str, float]:
    """The stage times an earlier sitting of this work folder recorded in ``transfer.json``
    (the work folder's settings are checked to be the same before this is read); {} without."""
    try:
        wall = json.loads(path.read_text()).get("wall_s", {})
    except (OSError, ValueError, AttributeError):
        return {}
    return (
        {k: float(v) for k, v in wall.items() if k != "total" and isinstance(v, (int, float))}
        if isinstance(wall, dict)
        else {}
    )


def table5_markdown(results: dict[str, Any]) -> str:
    """Our scores in the shape of Table 5, with the paper's Table 5 below for reference."""
    splits = results["splits"]
    n = len(splits)
    head = (
        "| | "
        + " | ".join(f"Real-Only {s['split']}" for s in splits)
        + " | "
        + " | ".join(f"DAVIS-Ag -> Real {s['split']}" for s in splits)
        + " |"
    )
    rule = "|---" * (2 * n + 1) + "|"
    rows = []
    for metric, title in (("map50", "mAP@50"), ("map50_95", "mAP@50:95")):
        cells = [f"{s[arm][metric]:.3f}" for arm, _ in ARMS for s in splits]
        rows.append(f"| {title} | " + " | ".join(cells) + " |")
    paper = ["| | Real-Only 1 | 2 | 3 | DAVIS-Ag -> Real 1 | 2 | 3 |", "|---" * 7 + "|"]
    for metric, title in (("map50", "mAP@50"), ("map50_95", "mAP@50:95")):
        cells = [f"{v:.3f}" for arm, _ in ARMS for v in PAPER_TABLE5[arm][metric]]
        paper.append(f"| {title} | " + " | ".join(cells) + " |")
    return "\n".join(
        [head, rule, *rows, "", "The paper's Table 5 (its real strawberry set, 654/159 images):", "", *paper]
    )


def write_results_md(results: dict[str, Any], path: Path, how: str = "") -> Path:
    """Write the Markdown report: what ran, the table, the paper's table, the wall time.

    Args:
        results: What :func:`run_transfer` returned.
        path: The Markdown file (written atomically).
        how: The machine it ran on, one line.
    """
    cfg = results["config"]
    pre, bud = cfg["pretrain_budget"], cfg["budget"]
    wall = results["wall_s"]
    lines = [
        "# Sim-to-real transfer (Table 5, section VI-A)",
        "",
        "Written by `davis-ag transfer --results`; every number below was measured by that run.",
        "",
        f"**Real set: {results['real_set']}.** "
        + ("These are stand-in numbers, not comparable to the paper's." if "stand-in" in results["real_set"] else ""),
        "",
        f"- Pre-training: {cfg['pretrain']} ({results['pretrain_images']['train']['images']} train images"
        + (
            f", boxes a median {results['pretrain_median_box_px']} px as the detector sees them"
            if results.get("pretrain_median_box_px") is not None
            else ""
        )
        + f"); {pre['epochs']} epochs at {pre['imgsz']} px, batch {pre['batch']}, device {pre['device']}.",
        f"- Real set: {results['real_images']} images, {len(results['splits'])} random splits of "
        f"{results['split_sizes']['train']} train / {results['split_sizes']['test']} test; "
        f"every run {bud['epochs']} epochs at {bud['imgsz']} px, batch {bud['batch']}; last-epoch weights scored.",
        "- Model: ultralytics' YOLOv5n built from `yolov5n.yaml` (anchor-free head), no downloaded weights.",
        *([f"- Machine: {how}"] if how else []),
        "",
        table5_markdown(results),
        "",
        "Wall time: " + ", ".join(f"{k} {v:.0f} s" for k, v in wall.items()) + ".",
        "",
    ]
    return write_text_atomic(path, "\n".join(lines))
