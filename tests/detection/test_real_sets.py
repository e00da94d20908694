"""Real sets in YOLO or COCO layout, and the paper's random splits of them."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from davis_ag.detection.coco_export import export_coco
from davis_ag.detection.real_sets import PAPER_TEST, PAPER_TRAIN, load_pool, split_sizes, write_split
from davis_ag.detection.yolo_export import export_yolo
from davis_ag.errors import UserError
from davis_ag.scene.specs import CROPS
from layout_factory import write_tiny_dataset


@pytest.fixture(scope="module")
def exports(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    root = tmp_path_factory.mktemp("real")
    write_tiny_dataset(root / "data", "sp", "strawberry", scenes=2, size=(64, 48))
    export_yolo(root / "data", root / "yolo", progress=False)
    export_coco(root / "data", root / "coco", progress=False)
    return root / "yolo", root / "coco"


def test_coco_and_yolo_layouts_give_the_same_pool(exports: tuple[Path, Path]) -> None:
    yolo, coco = exports
    from_yaml = load_pool(yolo / "data.yaml")
    from_folder = load_pool(yolo)
    from_coco = load_pool(coco / "annotations" / "instances_train.json")
    assert from_yaml.names == dict(enumerate(CROPS)) == from_coco.names
    train = {p.name.removesuffix(".jpeg"): lines for p, lines in from_yaml.items if "/train/" in str(p)}
    coco_lines = {
        f"{p.parent.parent.parent.name}_{p.parent.parent.name}_{p.stem}": lines for p, lines in from_coco.items
    }
    assert coco_lines == train and len(from_folder.items) == len(from_yaml.items) > len(train)


def test_splits_follow_the_paper_and_shrink_in_proportion(exports: tuple[Path, Path], tmp_path: Path) -> None:
    assert split_sizes(2000) == (PAPER_TRAIN, PAPER_TEST) == (654, 159)
    assert split_sizes(81) == (65, 16)
    with pytest.raises(UserError):
        split_sizes(1)
    pool = load_pool(exports[0])
    a = yaml.safe_load(write_split(pool, tmp_path / "a", 0, 30, 10).read_text())
    b = write_split(pool, tmp_path / "b", 1, 30, 10)
    names = lambda d, s: sorted(p.name for p in (d / "images" / s).iterdir())  # noqa: E731
    assert len(names(tmp_path / "a", "train")) == 30 and len(names(tmp_path / "a", "test")) == 10
    assert not set(names(tmp_path / "a", "train")) & set(names(tmp_path / "a", "test"))
    assert names(tmp_path / "a", "test") != names(b.parent, "test")
    assert a["val"] == "images/test" and a["names"][0] == "strawberry"


def test_bad_real_sets_are_one_line(tmp_path: Path) -> None:
    (tmp_path / "x.json").write_text("{}")
    for path, message in ((tmp_path, "not a labelled set"), (tmp_path / "x.json", "needs images")):
        with pytest.raises(UserError, match=message):
            load_pool(path)
    # A data YAML PyYAML cannot parse: its several-line error comes as one line with the place.
    (tmp_path / "bad.yaml").write_text("names: [fruit\ntrain: images\n")
    with pytest.raises(UserError, match=r"bad\.yaml: not valid YAML at line \d+, column \d+") as error:
        load_pool(tmp_path / "bad.yaml")
    assert "\n" not in str(error.value)
