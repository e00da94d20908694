"""torchvision imports and its NMS answers right on this machine's torch, CPU build or not
(docs/detection.md, "torchvision on a CPU-only torch")."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

SRC = Path(__file__).parents[2] / "src"

#: Whether ultralytics is installed, asked without importing it: an import here, before
#: prepare_ultralytics(), would replace PIL.Image.open for every later test in this process.
HAS_ULTRALYTICS = importlib.util.find_spec("ultralytics") is not None
needs_ultralytics = pytest.mark.skipif(not HAS_ULTRALYTICS, reason="ultralytics is not installed")

#: Three boxes: the second overlaps the first (IoU 0.81) and scores lower, the third stands apart.
#: NMS at IoU 0.5 keeps the first and the third, in score order.
CHECK = """
import torch
from davis_ag.detection.offline import prepare_ultralytics, torchvision_ops_load
compiled = torchvision_ops_load()
prepare_ultralytics()
import torchvision
boxes = torch.tensor([[0.0, 0.0, 10.0, 10.0], [1.0, 1.0, 10.0, 10.0], [20.0, 20.0, 30.0, 30.0]])
scores = torch.tensor([0.9, 0.8, 0.7])
print(compiled, torchvision.ops.nms(boxes, scores, 0.5).tolist())
"""


@needs_ultralytics
def test_torchvision_imports_and_its_nms_keeps_the_right_boxes() -> None:
    # A fresh interpreter: the operators must be defined before torchvision's first import.
    done = subprocess.run(
        [sys.executable, "-c", CHECK],
        capture_output=True,
        text=True,
        timeout=300,
        env={"PYTHONPATH": str(SRC), "PATH": "/usr/bin:/bin", "HOME": str(Path.home()), "YOLO_OFFLINE": "1"},
    )
    assert done.returncode == 0, done.stderr[-2000:]
    compiled, kept = done.stdout.split(maxsplit=1)
    assert compiled in ("True", "False")  # False: the CUDA wheel beside a CPU torch, patched
    assert kept.strip() == "[0, 2]"


DAMAGED = """
import io
import PIL.Image
from davis_ag.detection.offline import prepare_ultralytics
pil_open = PIL.Image.open
prepare_ultralytics()
assert PIL.Image.open is pil_open, "ultralytics' replacement of PIL.Image.open is still in place"
try:
    PIL.Image.open(io.BytesIO(b"not a jpeg"))
except PIL.UnidentifiedImageError:
    print("PIL's own error")
"""


@needs_ultralytics
def test_a_damaged_image_after_ultralytics_gets_pils_own_error() -> None:
    """Importing ultralytics replaced PIL.Image.open for the whole process: a damaged JPEG read
    after it raised ModuleNotFoundError (pi_heif) instead of PIL's error, which davis-ag turns
    into one line, and tried to install a package from the network."""
    done = subprocess.run(
        [sys.executable, "-c", DAMAGED],
        capture_output=True,
        text=True,
        timeout=300,
        env={"PYTHONPATH": str(SRC), "PATH": "/usr/bin:/bin", "HOME": str(Path.home()), "YOLO_OFFLINE": "1"},
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip() == "PIL's own error"
