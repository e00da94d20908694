"""COCO and YOLO exports: masks and boxes survive the round trip, and the tools load them."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from davis_ag.cli import main
from davis_ag.data.reader import open_dataset
from davis_ag.detection.coco_export import export_coco
from davis_ag.detection.instances import scenes_by_split
from davis_ag.detection.yolo_export import export_yolo, flat_name
from davis_ag.errors import UserError
from davis_ag.scene.specs import CROPS
from layout_factory import write_original_style_dataset, write_tiny_dataset
from wide_masks import widen_scene


@pytest.fixture(scope="module")
def dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("tiny")
    write_tiny_dataset(root, "sp", "strawberry", scenes=2, size=(64, 48))
    write_tiny_dataset(root, "sp", "tomato", scenes=1, size=(64, 48))
    # A depth image for one view, as the depth generator writes it (uint16 millimetres).
    depth = np.full((48, 64), 1234, dtype=np.uint16)
    Image.fromarray(depth).save(root / "Single-Strawberry" / "000" / "images" / "0002_depth.png")
    return root


def test_coco_masks_and_boxes_round_trip(dataset: Path, tmp_path: Path) -> None:
    from pycocotools import mask as mask_utils
    from pycocotools.coco import COCO

    counts = export_coco(dataset, tmp_path, progress=False)
    data = open_dataset(dataset)
    by_split = scenes_by_split(data)
    assert [s.id for s in by_split["test"]] == ["Single-Strawberry/001"]
    assert "Single-Tomato/000" in [s.id for s in by_split["train"]]
    for split, scenes in by_split.items():
        coco = COCO(str(tmp_path / "annotations" / f"instances_{split}.json"))
        assert counts[split]["images"] == len(coco.imgs) == sum(len(s) for s in scenes)
        categories = {c["name"]: c["id"] for c in coco.loadCats(coco.getCatIds())}
        # The paper's crops keep ids 1-3; the plant-library crops follow in specs.CROPS's order.
        assert categories == {name: i + 1 for i, name in enumerate(CROPS)}
        assert [categories[name] for name in ("strawberry", "tomato", "vine")] == [1, 2, 3]
        checked = 0
        for image in coco.imgs.values():
            view = data.scene(image["scene"]).view(image["view"])
            assert (dataset / image["file_name"]) == view.image_path
            seg = view.mask()
            anns = coco.loadAnns(coco.getAnnIds(imgIds=image["id"]))
            assert [a["attributes"]["fruit_id"] for a in anns] == [b.fruit_id for b in view.boxes]
            fractions = view.scene.metadata.visible_in(view.name)
            for ann, box in zip(anns, view.boxes):
                decoded = coco.annToMask(ann).astype(bool)
                assert np.array_equal(decoded, seg == box.fruit_id)
                assert ann["bbox"] == [box.xmin, box.ymin, box.width, box.height]
                assert list(mask_utils.toBbox(ann["segmentation"])) == ann["bbox"]
                assert ann["category_id"] == (1 if view.scene.crop == "strawberry" else 2)
                assert ann["attributes"]["visible_fraction"] == fractions[str(box.fruit_id)]
                checked += 1
            assert ("depth_file" in image) == (
                image["scene"] == "Single-Strawberry/000" and image["view"] == "0002.jpeg"
            )
        assert checked > 10


def test_coco_depth_path_points_at_the_depth_image(dataset: Path, tmp_path: Path) -> None:
    export_coco(dataset, tmp_path, splits=("train",), progress=False)
    images = json.loads((tmp_path / "annotations" / "instances_train.json").read_text())["images"]
    (with_depth,) = [i for i in images if "depth_file" in i]
    assert with_depth["depth_file"] == "Single-Strawberry/000/images/0002_depth.png"
    assert np.asarray(Image.open(dataset / with_depth["depth_file"])).max() == 1234


def test_coco_of_the_original_download_without_a_mask_keeps_the_boxes(tmp_path: Path) -> None:
    root = write_original_style_dataset(tmp_path / "orig", scenes=2, size=(64, 48), missing_mask=True)
    export_coco(root, tmp_path / "out", progress=False)
    data = json.loads((tmp_path / "out" / "annotations" / "instances_train.json").read_text())
    first = next(i for i in data["images"] if i["view"] == "0001.jpeg")
    anns = [a for a in data["annotations"] if a["image_id"] == first["id"]]
    assert anns and all("segmentation" not in a and a["attributes"]["visible_fraction"] is None for a in anns)


def test_coco_and_yolo_of_a_scene_with_16_bit_masks_keep_ids_above_255(tmp_path: Path) -> None:
    from pycocotools.coco import COCO

    root = write_tiny_dataset(tmp_path / "wide", "sp", "strawberry", scenes=2, size=(64, 48))
    for scene in ("000", "001"):
        widen_scene(root / "Single-Strawberry" / scene)
    export_coco(root, tmp_path / "coco", progress=False)
    export_yolo(root, tmp_path / "yolo", "segment", progress=False)
    data = open_dataset(root)
    checked = 0
    for split, scenes in scenes_by_split(data).items():
        coco = COCO(str(tmp_path / "coco" / "annotations" / f"instances_{split}.json"))
        for image in coco.imgs.values():
            view = data.scene(image["scene"]).view(image["view"])
            seg = view.mask()
            assert seg is not None and seg.dtype == np.uint16
            anns = coco.loadAnns(coco.getAnnIds(imgIds=image["id"]))
            assert [a["attributes"]["fruit_id"] for a in anns] == [b.fruit_id for b in view.boxes]
            for ann, box in zip(anns, view.boxes):
                assert box.fruit_id >= 300
                assert np.array_equal(coco.annToMask(ann).astype(bool), seg == box.fruit_id)
                assert ann["area"] == int((seg == box.fruit_id).sum()) > 0
                checked += 1
            label = tmp_path / "yolo" / "labels" / split / f"{flat_name(image['scene'] + '/' + image['view'])}.txt"
            lines = label.read_text().splitlines()
            assert len(lines) == len(view.boxes)
            for line, box in zip(lines, view.boxes):
                xy = np.array(line.split()[1:], dtype=float).reshape(-1, 2) * [64, 48]
                # Outlines through pixel centres: the extremes are the box's first and last pixels + 0.5.
                assert (xy[:, 0].min(), xy[:, 1].min()) == pytest.approx((box.xmin + 0.5, box.ymin + 0.5), abs=1e-3)
                assert (xy[:, 0].max(), xy[:, 1].max()) == pytest.approx((box.xmax + 0.5, box.ymax + 0.5), abs=1e-3)
    assert checked > 10


def _yolo_boxes(label: Path, width: int, height: int) -> list[tuple[int, float, float, float, float]]:
    rows = []
    for line in label.read_text().splitlines():
        cls, xc, yc, w, h = line.split()
        xc, yc, w, h = float(xc) * width, float(yc) * height, float(w) * width, float(h) * height
        rows.append((int(cls), xc - w / 2, yc - h / 2, w, h))
    return rows


def test_yolo_boxes_round_trip_and_load_in_ultralytics(dataset: Path, tmp_path: Path) -> None:
    counts = export_yolo(dataset, tmp_path, "detect", progress=False)
    data = open_dataset(dataset)
    for split, scenes in scenes_by_split(data).items():
        assert counts[split]["images"] == sum(len(s) for s in scenes)
        for scene in scenes:
            for view in scene:
                name = flat_name(f"{scene.id}/{view.name}")
                assert (tmp_path / "images" / split / f"{name}.jpeg").read_bytes() == view.image_path.read_bytes()
                rows = _yolo_boxes(tmp_path / "labels" / split / f"{name}.txt", 64, 48)
                assert len(rows) == len(view.boxes)
                for (cls, x, y, w, h), box in zip(rows, view.boxes):
                    assert cls == (0 if scene.crop == "strawberry" else 1)
                    assert np.allclose([x, y, w, h], [box.xmin, box.ymin, box.width, box.height], atol=1e-3)
    from davis_ag.detection.offline import prepare_ultralytics

    prepare_ultralytics()
    from ultralytics.data import YOLODataset
    from ultralytics.data.utils import check_det_dataset

    info = check_det_dataset(str(tmp_path / "data.yaml"))
    assert info["nc"] == len(CROPS) and info["names"][1] == "tomato"
    loaded = YOLODataset(img_path=info["val"], data=info, task="detect", augment=False, imgsz=64)
    n_boxes = sum(len(lab["cls"]) for lab in loaded.labels)
    assert len(loaded.labels) == counts["test"]["images"] and n_boxes == counts["test"]["instances"]


def test_yolo_polygons_fill_back_to_the_masks(dataset: Path, tmp_path: Path) -> None:
    import cv2

    export_yolo(dataset, tmp_path, "segment", splits=("test",), progress=False)
    scene = open_dataset(dataset).scene("Single-Strawberry/001")
    compared = 0
    for view in scene:
        seg = view.mask()
        lines = (tmp_path / "labels" / "test" / f"{flat_name(scene.id + '/' + view.name)}.txt").read_text().splitlines()
        for line, box in zip(lines, view.boxes):
            xy = np.array(line.split()[1:], dtype=float).reshape(-1, 2) * [64, 48]
            filled = np.zeros((48, 64), np.uint8)
            cv2.fillPoly(filled, [xy.astype(np.int32)], 1)  # as ultralytics rasterises polygons
            mask, filled = seg == box.fruit_id, filled.astype(bool)
            pieces = cv2.connectedComponents(mask.astype(np.uint8), connectivity=8)[0] - 1
            if pieces == 1:  # one outline: exactly the fruit's pixels
                assert np.array_equal(filled, mask)
                compared += 1
            else:  # pieces joined by seams: every pixel, plus the one-pixel seams between them
                assert not (mask & ~filled).any() and (filled & ~mask).sum() <= 2 * (box.width + box.height)
    assert compared > 5


def test_export_command_refuses_a_foreign_folder_and_writes_both_formats(
    dataset: Path, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    (tmp_path / "busy").mkdir()
    (tmp_path / "busy" / "notes.txt").write_text("mine")
    assert main(["export", "coco", str(dataset), str(tmp_path / "busy")]) == 2
    assert "not a coco export" in capsys.readouterr().err
    assert main(["export", "coco", str(tmp_path / "nothing"), str(tmp_path / "c")]) == 2
    assert main(["export", "coco", str(dataset), str(tmp_path / "c"), "--split", "test"]) == 0
    assert (tmp_path / "c" / "annotations" / "instances_test.json").is_file()
    assert main(["export", "yolo", str(dataset), str(tmp_path / "y")]) == 0
    out = capsys.readouterr().out
    assert "train:" in out and (tmp_path / "y" / "data.yaml").is_file()


def test_appearance_shift_changes_the_export_not_the_dataset(dataset: Path, tmp_path: Path) -> None:
    before = (dataset / "Single-Strawberry" / "001" / "images" / "0001.jpeg").read_bytes()
    assert main(["export", "yolo", str(dataset), str(tmp_path), "--split", "test", "--appearance-shift", "3"]) == 0
    shifted = tmp_path / "images" / "test" / "Single-Strawberry_001_0001.jpeg"
    assert (dataset / "Single-Strawberry" / "001" / "images" / "0001.jpeg").read_bytes() == before
    a = np.asarray(Image.open(shifted)).astype(float)
    b = np.asarray(Image.open(dataset / "Single-Strawberry" / "001" / "images" / "0001.jpeg")).astype(float)
    assert a.shape == b.shape and np.abs(a - b).mean() > 10


def _with_classes(dataset: Path, folder: Path) -> tuple[Path, dict[str, np.ndarray]]:
    """A copy of the tiny dataset with organ class images beside the views of one scene: sky on
    top, soil below, leaf and stem blocks, and fruit exactly where the instance mask has fruit."""
    import shutil

    copy = folder / "with-classes"
    shutil.copytree(dataset, copy)
    written = {}
    for view in open_dataset(copy).scene("Single-Strawberry/000"):
        mask = view.mask()
        classes = np.zeros(mask.shape, np.uint8)
        classes[mask.shape[0] // 3 :] = 1
        classes[2:6, 2:10] = 3
        classes[6:8, 2:10] = 4
        classes[mask != 255] = 2
        Image.fromarray(classes, mode="L").save(view.class_path)
        written[view.name] = classes
    return copy, written


def test_coco_organs_are_semantic_rle_masks(dataset: Path, tmp_path: Path) -> None:
    from pycocotools import mask as mask_utils
    from pycocotools.coco import COCO

    copy, written = _with_classes(dataset, tmp_path)
    export_coco(copy, tmp_path / "out", progress=False, organs=True)
    coco = COCO(str(tmp_path / "out" / "annotations" / "instances_train.json"))
    names = {c["id"]: c["name"] for c in coco.loadCats(coco.getCatIds())}
    assert {k: v for k, v in names.items() if k > 100} == {
        101: "soil",
        102: "fruit",
        103: "leaf",
        104: "stem",
        105: "trunk",
        106: "petiole",
        107: "peduncle",
        108: "flower",
        109: "structure",
        110: "cover",
    }
    checked = 0
    for image in coco.loadImgs(coco.getImgIds()):
        organs = [a for a in coco.loadAnns(coco.getAnnIds(imgIds=image["id"])) if a["category_id"] > 100]
        classes = written.get(image["view"]) if image["scene"] == "Single-Strawberry/000" else None
        if classes is None:
            assert organs == []  # views without a class image keep their fruit labels only
            continue
        assert sorted(a["category_id"] - 100 for a in organs) == sorted(set(np.unique(classes).tolist()) - {0})
        for annotation in organs:
            mask = mask_utils.decode(annotation["segmentation"]).astype(bool)
            assert np.array_equal(mask, classes == annotation["category_id"] - 100)
            assert annotation["area"] == mask.sum() and annotation["attributes"]["semantic"]
            checked += 1
    assert checked > 0
    assert len({a["id"] for a in coco.loadAnns(coco.getAnnIds())}) == len(coco.getAnnIds())  # ids unique


def test_yolo_organs_are_polygons_after_the_crops(dataset: Path, tmp_path: Path) -> None:
    import yaml

    copy, written = _with_classes(dataset, tmp_path)
    with pytest.raises(UserError, match="--task segment"):
        export_yolo(copy, tmp_path / "boxes", "detect", progress=False, organs=True)
    export_yolo(copy, tmp_path / "out", "segment", progress=False, organs=True)
    names = yaml.safe_load((tmp_path / "out" / "data.yaml").read_text())["names"]
    crops = len(CROPS)
    assert names == {
        **dict(enumerate(CROPS)),
        crops: "organ_soil",
        crops + 1: "organ_fruit",
        crops + 2: "organ_leaf",
        crops + 3: "organ_stem",
        crops + 4: "organ_trunk",
        crops + 5: "organ_petiole",
        crops + 6: "organ_peduncle",
        crops + 7: "organ_flower",
        crops + 8: "organ_structure",
        crops + 9: "organ_cover",
    }
    assert list(names.values())[:3] == ["strawberry", "tomato", "vine"]  # the paper's crops keep 0-2
    import cv2
    from scipy.ndimage import binary_fill_holes

    for name, classes in written.items():
        label = tmp_path / "out" / "labels" / "train" / f"{flat_name('Single-Strawberry/000/' + name)}.txt"
        organ = [line.split() for line in label.read_text().splitlines() if int(line.split()[0]) >= crops]
        assert {int(line[0]) for line in organ} == {crops - 1 + v for v in set(np.unique(classes).tolist()) - {0}}
        # Each part of a class is its own polygon: filled, they give the class's pixels back. Joined
        # into one polygon with seams (as before), the fruit's separate discs filled in a fan.
        height, width = classes.shape
        for value in set(np.unique(classes).tolist()) - {0, 1}:  # the soil's outline has no holes
            filled = np.zeros((height, width), np.uint8)
            for line in organ:
                if int(line[0]) == crops - 1 + value:
                    xy = np.array(line[1:], dtype=float).reshape(-1, 2) * [width, height]
                    cv2.fillPoly(filled, [xy.astype(np.int32)], 1)
            truth = classes == value
            # Every pixel of the class but the specks of one or two pixels (no outline to draw), and
            # beyond it only the holes a part encloses (polygons have none).
            count, parts = cv2.connectedComponents(truth.astype(np.uint8), connectivity=8)
            specks = np.isin(parts, [k for k in range(1, count) if (parts == k).sum() <= 2])
            assert np.array_equal(filled.astype(bool), binary_fill_holes(truth) & ~specks), (name, value)
