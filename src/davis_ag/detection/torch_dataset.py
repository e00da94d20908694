"""A PyTorch ``Dataset`` over a DAVIS-Ag folder, in torchvision's detection convention.

Each item is ``(image, target)``: ``image`` a float tensor ``3 x H x W`` in [0, 1]; ``target`` a
dict with what torchvision's detectors (Faster/Mask R-CNN, RetinaNet, FCOS, SSD) train on and
what DAVIS-Ag adds:

- ``boxes``: float ``N x 4``, ``(x1, y1, x2, y2)`` in continuous pixel coordinates
  (``x2 = xmin + width``, so a one-pixel fruit is one pixel wide);
- ``labels``: int64 ``N``, the crop's category (1 strawberry, 2 tomato, 3 vine; 0 is background);
- ``masks``: uint8 ``N x H x W`` (``0 x H x W`` without a ``_seg.png``);
- ``image_id``, ``area`` (mask pixels, else box area), ``iscrowd`` (zeros);
- ``fruit_ids``: int64 ``N``, stable across the scene's views; ``visible_fraction``: float ``N``
  (NaN where unknown); ``depth``: float ``1 x H x W`` in metres from ``NNNN_depth.png``
  (uint16 millimetres, 0 = no depth), or ``None`` where the view has none.

torchvision itself is not needed (its PyPI wheels need CUDA torch); any torchvision detector
takes these items as they are. Batch them with :func:`collate` (lists, as the detectors want).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import torch

from davis_ag.data.reader import open_dataset
from davis_ag.detection.instances import label_view, scenes_by_split
from davis_ag.errors import UserError
from davis_ag.formats.layout import read_depth

Target = dict[str, Any]


class DavisAgDetection(torch.utils.data.Dataset):
    """Views of a DAVIS-Ag dataset (one split, or all) as detection samples.

    Only ``(scene index, view name)`` pairs are held; pixels are read per item.

    Args:
        root: Dataset root, group folder or scene folder.
        split: ``train``, ``test`` (splits.json, else the benchmark's 70/30 split) or ``all``.
        transforms: Optional ``(image, target) -> (image, target)``, as in torchvision's references.
        with_masks: Decode instance masks (skip them for box-only detectors).
        skip_empty: Leave out views with no fruit (torchvision's R-CNNs accept them, some losses do not).
    """

    def __init__(
        self,
        root: str | Path,
        split: str = "train",
        transforms: Callable[[torch.Tensor, Target], tuple[torch.Tensor, Target]] | None = None,
        with_masks: bool = True,
        skip_empty: bool = False,
    ) -> None:
        dataset = open_dataset(root)
        if split == "all":
            self.scenes = list(dataset.scenes)
        elif split in ("train", "test"):
            self.scenes = scenes_by_split(dataset)[split]
        else:
            raise UserError(f"unknown split {split!r}: choose train, test or all")
        if not self.scenes:
            raise UserError(f"{dataset.root}: the {split} split has no scene; use split='all'")
        self.items = [
            (i, view.name) for i, scene in enumerate(self.scenes) for view in scene if view.boxes or not skip_empty
        ]
        self.transforms = transforms
        self.with_masks = with_masks

    def __len__(self) -> int:
        return len(self.items)

    def __getitem__(self, index: int) -> tuple[torch.Tensor, Target]:
        scene_index, name = self.items[index]
        view = self.scenes[scene_index].views[name]
        item = label_view(view, self.with_masks)
        image = torch.from_numpy(np.array(view.image())).permute(2, 0, 1).float().div_(255)
        n, shape = len(item.instances), (item.height, item.width)
        boxes = torch.tensor([inst.xyxy for inst in item.instances], dtype=torch.float32).reshape(n, 4)
        masks = [inst.mask for inst in item.instances if inst.mask is not None]
        mask_tensor = (
            torch.from_numpy(np.stack(masks).astype(np.uint8))
            if len(masks) == n and n
            else torch.zeros((0, *shape), dtype=torch.uint8)
        )
        area = (
            mask_tensor.flatten(1).sum(1).float()
            if len(mask_tensor) == n and n
            else (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])
        )
        target: Target = {
            "boxes": boxes,
            "labels": torch.tensor([inst.category for inst in item.instances], dtype=torch.int64),
            "masks": mask_tensor,
            "image_id": index,
            "area": area,
            "iscrowd": torch.zeros(n, dtype=torch.int64),
            "fruit_ids": torch.tensor([inst.box.fruit_id for inst in item.instances], dtype=torch.int64),
            "visible_fraction": torch.tensor(
                [np.nan if inst.visible_fraction is None else inst.visible_fraction for inst in item.instances],
                dtype=torch.float32,
            ),
            "depth": None if item.depth is None else _depth_metres(item.depth, shape),
            "scene": view.scene.id,
            "view": view.name,
        }
        if self.transforms is not None:
            image, target = self.transforms(image, target)
        return image, target


def _depth_metres(path: Path, shape: tuple[int, int]) -> torch.Tensor:
    metres = read_depth(path)
    if metres.shape != shape:
        raise UserError(
            f"{path}: depth is {metres.shape[1]}x{metres.shape[0]}, image {shape[1]}x{shape[0]}; regenerate the scene"
        )
    return torch.from_numpy(metres).unsqueeze(0)


def collate(batch: list[tuple[torch.Tensor, Target]]) -> tuple[list[torch.Tensor], list[Target]]:
    """Batch detection samples as two lists (images of any size), as torchvision's detectors take them."""
    images, targets = zip(*batch)
    return list(images), list(targets)
