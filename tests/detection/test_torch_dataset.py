"""The PyTorch dataset: torchvision's detection convention, and a torchvision detector learns from it."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import torch
from PIL import Image

from davis_ag.data.reader import open_dataset
from davis_ag.detection.torch_dataset import DavisAgDetection, collate
from davis_ag.errors import UserError
from layout_factory import write_tiny_dataset


@pytest.fixture(scope="module")
def dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = write_tiny_dataset(tmp_path_factory.mktemp("tiny"), "sp", "strawberry", scenes=2, size=(64, 48))
    depth = np.arange(64 * 48, dtype=np.uint16).reshape(48, 64) + 500
    Image.fromarray(depth).save(root / "Single-Strawberry" / "000" / "images" / "0003_depth.png")
    return root


def test_items_follow_the_detection_convention(dataset: Path) -> None:
    data = DavisAgDetection(dataset, "train")
    scene = open_dataset(dataset).scene("Single-Strawberry/000")
    assert len(data) == len(scene)
    for index in (0, 2, 7):
        image, target = data[index]
        view = scene.view(target["view"])
        assert image.dtype == torch.float32 and image.shape == (3, 48, 64) and 0 <= image.min() <= image.max() <= 1
        assert torch.allclose(image, torch.from_numpy(view.image().copy()).permute(2, 0, 1).float() / 255)
        n = len(view.boxes)
        assert target["boxes"].shape == (n, 4) and target["labels"].tolist() == [1] * n
        assert target["fruit_ids"].tolist() == [b.fruit_id for b in view.boxes]
        seg = view.mask()
        for box, xyxy, mask in zip(view.boxes, target["boxes"], target["masks"]):
            assert xyxy.tolist() == [box.xmin, box.ymin, box.xmin + box.width, box.ymin + box.height]
            assert torch.equal(mask.bool(), torch.from_numpy(seg == box.fruit_id))
        fractions = scene.metadata.visible_in(view.name)
        assert [round(v, 4) for v in target["visible_fraction"].tolist()] == [
            fractions[str(b.fruit_id)] for b in view.boxes
        ]
        if view.name == "0003.jpeg":
            assert target["depth"].shape == (1, 48, 64) and math.isclose(
                target["depth"][0, 0, 1].item(), 0.501, rel_tol=1e-6
            )
        else:
            assert target["depth"] is None


def test_test_split_and_bad_split(dataset: Path) -> None:
    assert {t["scene"] for _, t in DavisAgDetection(dataset, "test", with_masks=False)} == {"Single-Strawberry/001"}
    with pytest.raises(UserError, match="unknown split"):
        DavisAgDetection(dataset, "val")


def test_a_torchvision_detector_learns_from_it(dataset: Path) -> None:
    from davis_ag.detection.offline import prepare_ultralytics

    prepare_ultralytics()  # makes torchvision importable on the CPU build of torch
    from torchvision.models.detection import FCOS
    from torchvision.models.detection.anchor_utils import AnchorGenerator

    torch.manual_seed(0)
    data = DavisAgDetection(dataset, "train", with_masks=False, skip_empty=True)
    loader = torch.utils.data.DataLoader(data, batch_size=4, shuffle=False, collate_fn=collate)
    # torchvision's FCOS on a small backbone (stride 4, 32 channels): seconds on a CPU.
    backbone = torch.nn.Sequential(
        torch.nn.Conv2d(3, 16, 3, 2, 1),
        torch.nn.ReLU(),
        torch.nn.Conv2d(16, 32, 3, 2, 1),
        torch.nn.ReLU(),
        torch.nn.Conv2d(32, 32, 3, 1, 1),
        torch.nn.ReLU(),
    )
    backbone.out_channels = 32
    anchors = AnchorGenerator(sizes=((8,),), aspect_ratios=((1.0,),))
    model = FCOS(
        backbone, num_classes=4, min_size=48, max_size=64, anchor_generator=anchors, center_sampling_radius=2.0
    )
    optimiser = torch.optim.AdamW(model.parameters(), lr=3e-3)
    images, targets = next(iter(loader))
    model.train()
    losses = []
    for _ in range(15):  # the same batch: a detector that can learn from the targets overfits it
        loss = sum(model(images, [{"boxes": t["boxes"], "labels": t["labels"]} for t in targets]).values())
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
        losses.append(loss.item())
    assert all(math.isfinite(v) for v in losses) and losses[-1] < 0.8 * losses[0]
    model.eval()
    with torch.no_grad():
        (detections,) = model(images[:1])
    assert set(detections) == {"boxes", "scores", "labels"}
