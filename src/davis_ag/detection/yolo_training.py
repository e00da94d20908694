"""Train and score a YOLOv5n with ultralytics, on the CPU or a GPU, offline.

The model is built from ultralytics' ``yolov5n.yaml`` (no weights are downloaded): ultralytics'
YOLOv5n, i.e. the paper's YOLOv5 nano backbone and neck with ultralytics' anchor-free head (the
"u" variant); the paper used the original anchor-based YOLOv5n of the yolov5 repository.
Fine-tuning starts from a checkpoint: ultralytics carries every weight whose shape matches and
re-initialises the class rows of the head when the class lists differ.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import torch

from davis_ag.detection.offline import prepare_ultralytics

#: The detector of section VI-A, built from its YAML.
MODEL_YAML = "yolov5n.yaml"
#: Its finest detection grid, in input pixels: a box much smaller than a cell rarely holds the
#: cell centre the anchor-free head assigns it to, so it teaches the detector nothing.
FINEST_STRIDE = 8


def median_box_side(export: Path, split: str, imgsz: int) -> float | None:
    """The median side (square root of the area) of an export's boxes as the detector sees them,
    in input pixels at ``imgsz`` (the longer image side scaled to it); None without boxes.

    Args:
        export: A YOLO export's folder (``images/<split>``, ``labels/<split>``).
        split: ``train`` or ``test``.
        imgsz: The training image size.
    """
    from PIL import Image

    images = sorted((export / "images" / split).glob("*"))
    if not images:
        return None
    with Image.open(images[0]) as first:
        width, height = first.size  # an export's views share one size
    scale = imgsz / max(width, height)
    sides = [
        (float(w) * width * float(h) * height) ** 0.5 * scale
        for label in (export / "labels" / split).glob("*.txt")
        for _, _, _, w, h in (line.split()[:5] for line in label.read_text().splitlines() if line.strip())
    ]
    return float(sorted(sides)[len(sides) // 2]) if sides else None


@dataclass(frozen=True)
class Budget:
    """What every training run of one experiment gets (the same for both arms).

    Attributes:
        epochs: Passes over the training set.
        imgsz: Square input size in pixels.
        batch: Images per step.
        device: ``cpu``, ``0`` (first GPU), ...
        workers: Data-loading processes (0 loads in the training process).
    """

    epochs: int = 100
    imgsz: int = 640
    batch: int = 16
    device: str = "cpu"
    workers: int = 0


def train(data_yaml: Path, out_dir: Path, budget: Budget, seed: int, start: Path | None = None) -> Path:
    """Train one YOLOv5n; returns the last epoch's checkpoint (no model selection on test data).

    Args:
        data_yaml: ultralytics data YAML (``val`` is only looked at after the last epoch).
        out_dir: Folder for this run (ultralytics writes ``weights/last.pt`` there).
        budget: Epochs, image size, batch, device.
        seed: Seeds ultralytics' run.
        start: Checkpoint to fine-tune from; ``None`` trains from scratch (random init).

    Returns:
        Path of ``weights/last.pt``. An existing one is reused (the run resumes nothing half-done:
        ultralytics writes it when training ends).
    """
    last = out_dir / "weights" / "last.pt"
    done = out_dir / "done.json"
    if last.is_file() and done.is_file():
        return last
    prepare_ultralytics()
    from ultralytics import YOLO

    model = YOLO(str(start) if start else MODEL_YAML, task="detect")
    carried: dict[str, float] = {}
    if start:
        model.add_callback(
            "on_train_start",
            lambda trainer: carried.update(start_weights_carried=carried_fraction(start, trainer.model)),
        )
    model.train(
        data=str(data_yaml),
        epochs=budget.epochs,
        imgsz=budget.imgsz,
        batch=budget.batch,
        device=budget.device,
        workers=budget.workers,
        project=str(out_dir.parent),
        name=out_dir.name,
        exist_ok=True,
        plots=False,
        val=False,
        seed=seed,
        deterministic=True,
        # ultralytics drops a checkpoint's weights when pretrained is False
        pretrained=start is not None,
        amp=budget.device != "cpu",
        verbose=False,
        patience=0,
        close_mosaic=min(10, budget.epochs // 2),
        # One optimiser step per batch: by default ultralytics accumulates gradients up to 64
        # images, which on a set of a few hundred images leaves a handful of steps per run.
        nbs=budget.batch,
    )
    done.write_text(json.dumps({"epochs": budget.epochs, "start": str(start) if start else None, **carried}) + "\n")
    return last


def carried_fraction(start: Path, model: torch.nn.Module) -> float:
    """Share of a checkpoint's weight tensors that a model holds unchanged (1.0: all carried over).

    Measured when training starts, it shows that fine-tuning began from the pre-trained weights.
    """
    from ultralytics.nn.tasks import load_checkpoint

    source = load_checkpoint(str(start))[0].float().state_dict()
    target = model.state_dict()
    same = sum(
        1
        for k, v in source.items()
        if k in target and target[k].shape == v.shape and torch.equal(target[k].float().cpu(), v)
    )
    return round(same / max(len(source), 1), 4)


def evaluate(weights: Path, data_yaml: Path, budget: Budget, split: str = "test") -> dict[str, float]:
    """Score a checkpoint on one split: COCO-style mAP at IoU 0.5 and averaged over 0.5:0.95.

    Returns:
        ``{"map50": ..., "map50_95": ..., "precision": ..., "recall": ...}``.
    """
    prepare_ultralytics()
    from ultralytics import YOLO

    metrics = YOLO(str(weights), task="detect").val(
        data=str(data_yaml),
        split=split,
        imgsz=budget.imgsz,
        batch=budget.batch,
        device=budget.device,
        workers=budget.workers,
        plots=False,
        verbose=False,
        save_json=False,
        project=str(weights.parent.parent),
        name=f"val-{split}",
        exist_ok=True,
    )
    box = metrics.box
    return {"map50": float(box.map50), "map50_95": float(box.map), "precision": float(box.mp), "recall": float(box.mr)}
