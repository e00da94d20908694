"""Malformed datasets that ended in a traceback or a wrong answer: each is now one line from
``validate`` (a report naming the file) and from the reader (a :class:`UserError`), or a right
answer. The hypothesis test of test_bad_files.py draws damage at random; these are the cases a
review found it had not drawn."""

from __future__ import annotations

import json
import shutil
import struct
import zlib
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from davis_ag.data.reader import Box, exposure_rate, open_dataset
from davis_ag.data.validate import validate_dataset
from davis_ag.errors import UserError
from layout_factory import write_tiny_dataset

SCENE = Path("Single-Strawberry") / "000"


@pytest.fixture(scope="module")
def pristine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_tiny_dataset(tmp_path_factory.mktemp("pristine") / "data", "sp", "strawberry", scenes=2)


def _edit_json(path: Path, change: Callable[[dict], None]) -> None:
    doc = json.loads(path.read_text())
    change(doc)
    path.write_text(json.dumps(doc))


def _with_depth(scene: Path, pose: list | None = None) -> None:
    """A depth image for view 0001 as our writer records it, and optionally another pose."""
    with Image.open(scene / "images" / "0001.jpeg") as image:
        size = image.size
    Image.fromarray(np.full(size[::-1], 500, np.uint16)).save(scene / "images" / "0001_depth.png")
    _edit_json(scene / "scene.json", lambda d: d.update(depth={"file": "images/NNNN_depth.png", "unit": "mm"}))
    if pose is not None:
        _edit_json(scene / "annotations.json", lambda d: d["0001.jpeg"].update(pose=pose))


def _first_boxed(scene: Path) -> tuple[str, list]:
    doc = json.loads((scene / "annotations.json").read_text())
    name = next(n for n in sorted(doc) if doc[n]["bounding_boxes"])
    return name, doc[name]["bounding_boxes"][0]


def _fruit_id_300(scene: Path) -> None:
    name, box = _first_boxed(scene)
    fruit = box[4]
    _edit_json(scene / "annotations.json", lambda d: d[name]["bounding_boxes"][0].__setitem__(4, 300))
    _edit_json(scene / "scene.json", lambda d: d["fruits"].append({**d["fruits"][0], "id": 300}))
    _with_depth(scene)
    assert fruit != 300


def _short_centre(scene: Path) -> None:
    _edit_json(scene / "scene.json", lambda d: [f.update(center=f["center"][:2]) for f in d["fruits"]])
    _with_depth(scene)


def _raw(text: str) -> Callable[[Path], None]:
    def write(scene: Path) -> None:
        (scene / "annotations.json").write_text(text)

    return write


def _duplicate_view(scene: Path) -> None:
    text = (scene / "annotations.json").read_text()
    doc = json.loads(text)
    twice = json.dumps({**doc["0001.jpeg"], "forward": ""})
    (scene / "annotations.json").write_text(text.rstrip()[:-1] + f', "0001.jpeg": {twice}}}')


def _rename_view(new: str) -> Callable[[Path], None]:
    return lambda scene: _edit_json(scene / "annotations.json", lambda d: d.__setitem__(new, d.pop("0002.jpeg")))


def _link_out(kind: str) -> Callable[[Path], None]:
    def link(scene: Path) -> None:
        outside = scene.parents[2] / "outside"
        outside.mkdir(exist_ok=True)
        if kind == "depth":
            _with_depth(scene)
            source = scene / "images" / "0001_depth.png"
        else:
            mask = np.asarray(Image.open(scene / "images" / "0002_seg.png"))
            source = scene / "images" / "0002_class.png"
            Image.fromarray(np.where(mask != 255, 2, 0).astype(np.uint8)).save(source)
        shutil.move(source, outside / source.name)
        source.symlink_to(outside / source.name)

    return link


def _bomb(scene: Path) -> None:
    """A 100-byte PNG whose header claims 20000 x 20000 pixels."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", 20000, 20000, 8, 0, 0, 0, 0)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(b"")) + chunk(b"IEND", b"")
    (scene / "images" / "0001_seg.png").write_bytes(png)


CASES: dict[str, tuple[Callable[[Path], None], str]] = {
    "a short pose beside a depth image": (lambda s: _with_depth(s, [0, 0, 1]), "annotations.json"),
    "a fruit id of 300 beside a depth image": (_fruit_id_300, "annotations.json"),
    "a fruit centre of two numbers beside a depth image": (_short_centre, "scene.json"),
    "a number of 5,000 digits": (_raw('{"0001.jpeg": {"pose": [' + "9" * 5000 + "]}}"), "annotations.json"),
    "nesting 100,000 deep": (_raw("[" * 100_000), "annotations.json"),
    "a view named twice": (_duplicate_view, "annotations.json"),
    "a view named by a superscript digit": (_rename_view("²"), "annotations.json"),
    "a view named with a NUL": (_rename_view("00\x001"), "annotations.json"),
    "a depth image linked out of the dataset": (_link_out("depth"), "0001_depth.png"),
    "a class image linked out of the dataset": (_link_out("classes"), "0002_class.png"),
    "a PNG claiming 20000 x 20000 pixels": (_bomb, "0001_seg.png"),
}


def _read_everything(root: Path) -> None:
    dataset = open_dataset(root)
    _ = dataset.splits
    for scene in dataset.scenes:
        _ = scene.metadata
        for view in scene.views.values():
            view.image(), view.mask(), view.depth(), view.classes()
            for action in scene.actions:
                view.next(action)


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_malformed_scene_is_one_line_from_validate_and_from_the_reader(
    case: str, pristine: Path, tmp_path: Path
) -> None:
    damage, named = CASES[case]
    root = Path(shutil.copytree(pristine, tmp_path / "data"))
    damage(root / SCENE)
    report = validate_dataset(root, workers=1)
    problems = [str(p) for p in report.problems]
    assert not report.ok and any(named in p for p in problems), problems
    assert all("\n" not in p for p in problems)
    try:
        _read_everything(root)
    except UserError as error:
        assert "\n" not in str(error)


def test_links_out_of_the_dataset_are_named_and_never_decoded(pristine: Path, tmp_path: Path) -> None:
    root = Path(shutil.copytree(pristine, tmp_path / "data"))
    _link_out("depth")(root / SCENE)
    _link_out("classes")(root / SCENE)
    problems = [str(p) for p in validate_dataset(root, workers=1).problems]
    for name in ("0001_depth.png", "0002_class.png"):
        assert any(name in p and "points outside the dataset" in p for p in problems), problems


def test_a_duplicate_view_is_named(pristine: Path, tmp_path: Path) -> None:
    root = Path(shutil.copytree(pristine, tmp_path / "data"))
    _duplicate_view(root / SCENE)
    problems = [str(p) for p in validate_dataset(root, workers=1).problems]
    assert any("'0001.jpeg' appears twice" in p for p in problems), problems
    with pytest.raises(UserError, match="appears twice"):
        _read_everything(root)


@pytest.mark.parametrize("box", [Box(-10, 10, 4, 10, 3), Box(-3, 10, 2, 10, 3), Box(5, -20, 4, 6, 3)])
def test_a_box_wholly_off_the_image_exposes_nothing(box: Box) -> None:
    """A negative slice end counted from the far edge: exposure rates of 7.5 and 15."""
    mask = np.full((48, 64), 3, dtype=np.uint8)
    assert exposure_rate(mask, box) == 0.0


@pytest.mark.parametrize("seed", [-5, 1.5, "1e400", True])
def test_a_bad_seed_in_dataset_json_is_one_line_for_the_fallback_split(
    seed: object, pristine: Path, tmp_path: Path
) -> None:
    from davis_ag.benchmark.splits import dataset_splits

    root = Path(shutil.copytree(pristine, tmp_path / "data"))
    (root / "splits.json").unlink()
    raw = json.dumps({"seed": 0}).replace("0", "1e400") if seed == "1e400" else json.dumps({"seed": seed})
    (root / "dataset.json").write_text(raw)
    with pytest.raises(UserError, match="seed"):
        dataset_splits(open_dataset(root))
