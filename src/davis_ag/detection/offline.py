"""Make ultralytics work here: offline, on a CPU-only torch, and without fetching anything.

Two things stand between ``pip install davis-ag[detect]`` and a YOLO training run on a machine
without network access and without CUDA:

1. ultralytics reaches out by default: it downloads ``Arial.ttf`` for its plots, checks and
   auto-installs requirements, sends usage events and probes DNS. Its own switches turn all of
   that off (``YOLO_OFFLINE``, ``YOLO_AUTOINSTALL``, ``ULTRALYTICS_SKIP_REQUIREMENTS_CHECKS``,
   the ``sync`` setting); they are read when ultralytics is first imported, so
   :func:`prepare_ultralytics` sets them before that. Its settings and font live in
   ``YOLO_CONFIG_DIR`` (ours unless you set one), where matplotlib's DejaVu Sans is placed under
   the font names it asks for, so no font is ever downloaded.
2. PyPI's torchvision wheels are linked against CUDA torch; with the CPU build of torch their
   compiled operators cannot load, and torchvision 0.28 then fails at import (it registers
   meta kernels for ``torchvision::nms`` and ``qnms`` unconditionally). ultralytics imports
   torchvision and, once imported, calls ``torchvision.ops.nms``. Where (and only where) the
   compiled operators fail to load, we define those two operator schemas, give ``nms`` a CPU
   kernel: ultralytics' own pure-torch ``TorchNMS.nms``, the one it uses without torchvision,
   and tell torchvision's Python side (``extension._has_ops``) that operators are there. Every
   other compiled torchvision operator (``roi_align``, ``deform_conv2d``...) stays missing and
   fails with "operator torchvision::... does not exist" if called.
"""

from __future__ import annotations

import importlib.util
import os
import shutil
from pathlib import Path
from types import ModuleType

from davis_ag.errors import UserError

#: Where ultralytics keeps its settings and font unless ``YOLO_CONFIG_DIR`` is set.
DEFAULT_CONFIG_DIR = Path.home() / ".config" / "davis-ag" / "ultralytics"
_OFFLINE_ENV = {"YOLO_OFFLINE": "1", "YOLO_AUTOINSTALL": "0", "ULTRALYTICS_SKIP_REQUIREMENTS_CHECKS": "1"}
_state: dict[str, object] = {}


def torchvision_ops_load() -> bool:
    """Whether the installed torchvision's compiled operators load into this torch.

    Raises:
        UserError: when torchvision is not installed.
    """
    import torch

    spec = importlib.util.find_spec("torchvision")
    if spec is None or spec.origin is None:
        raise UserError(
            "torchvision is not installed: pip install 'davis-ag[detect]' "
            "(after torch, so that no other torch build is pulled in)"
        )
    libraries = sorted(Path(spec.origin).parent.glob("_C*.so"))
    if not libraries:
        return False
    try:
        torch.ops.load_library(str(libraries[0]))
    except OSError:
        return False
    return True


def _define_cpu_nms() -> None:
    import torch
    from ultralytics.utils.nms import TorchNMS

    library = torch.library.Library("torchvision", "DEF")
    library.define("nms(Tensor dets, Tensor scores, float iou_threshold) -> Tensor")
    library.define("qnms(Tensor dets, Tensor scores, float iou_threshold) -> Tensor")
    library.impl("nms", lambda dets, scores, iou: TorchNMS.nms(dets, scores, iou), "CPU")
    _state["library"] = library  # the registration lasts as long as this object


def _place_fonts(config_dir: Path) -> None:
    import matplotlib

    source = Path(matplotlib.get_data_path()) / "fonts" / "ttf" / "DejaVuSans.ttf"
    for name in ("Arial.ttf", "Arial.Unicode.ttf"):  # the two ultralytics asks for (ASCII names or not)
        font = config_dir / name
        if not font.is_file():
            config_dir.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(source, font)


def prepare_ultralytics() -> ModuleType:
    """Import ultralytics set up to work offline on this machine (see the module docstring).

    Idempotent. Call it before anything imports ultralytics or torchvision.

    Returns:
        The ``ultralytics`` module.

    Raises:
        UserError: when ultralytics or torchvision is missing, or ultralytics was imported first.
    """
    if isinstance(prepared := _state.get("ultralytics"), ModuleType):
        return prepared
    import sys

    from PIL import Image

    pil_open = Image.open  # before anything of ultralytics is imported (see below)

    if "ultralytics" in sys.modules:
        raise UserError(
            "ultralytics was imported before davis_ag.detection.offline.prepare_ultralytics(); "
            "call it first so that ultralytics starts offline"
        )
    if importlib.util.find_spec("ultralytics") is None:
        raise UserError("ultralytics is not installed: pip install 'davis-ag[detect]'")
    for key, value in _OFFLINE_ENV.items():
        os.environ.setdefault(key, value)
    os.environ.setdefault("YOLO_CONFIG_DIR", str(DEFAULT_CONFIG_DIR))
    patch = "torchvision" not in sys.modules and not torchvision_ops_load()
    if patch:
        _define_cpu_nms()
    import torchvision.extension  # now importable

    if patch:
        # torchvision.ops.nms asks this before calling torch.ops.torchvision.nms, defined above.
        torchvision.extension._has_ops = lambda: True
    import ultralytics
    from ultralytics.utils import SETTINGS, USER_CONFIG_DIR

    # Importing ultralytics replaces PIL.Image.open, for the whole process, with one that meets an
    # image PIL cannot identify by installing pi-heif from the network. davis-ag reads JPEG and PNG
    # only, works offline, and reports a damaged file in one line from PIL's own error: the
    # original comes back.
    Image.open = pil_open

    _place_fonts(Path(USER_CONFIG_DIR))
    if SETTINGS.get("sync"):
        SETTINGS.update({"sync": False})
    _state["ultralytics"] = ultralytics
    return ultralytics
