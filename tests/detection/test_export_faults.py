"""Exports trust nothing they read and leave nothing half-written (issue 33 cases 6 and 7)."""

from __future__ import annotations

import errno
import json
import os
import shutil
from pathlib import Path

import pytest
from PIL import Image

from davis_ag import cli
from layout_factory import write_tiny_dataset

VIEW = Path("Single-Strawberry") / "000" / "images" / "0001.jpeg"


@pytest.fixture(scope="module")
def pristine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_tiny_dataset(tmp_path_factory.mktemp("pristine"), "sp", "strawberry", scenes=2, size=(64, 48))


@pytest.fixture()
def data(pristine: Path, tmp_path: Path) -> Path:
    """A copy to damage."""
    return Path(shutil.copytree(pristine, tmp_path / "DATA"))


def export(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """``davis-ag export ARGV``: exit status, stdout, and stderr's lines that are no progress bar."""
    code = cli.main(["export", *argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    lines = [line.split("]")[-1] if "view/s]" in line else line for line in err.replace("\r", "\n").splitlines()]
    return code, out, "".join(f"{line}\n" for line in lines if line.strip())


@pytest.mark.parametrize("fmt", ["coco", "yolo"])
def test_an_image_linked_out_of_the_dataset_is_never_read(
    fmt: str, data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Case 6: YOLO copied a view image that is a symlink to a file outside the dataset."""
    outside = tmp_path / "secret.jpeg"
    shutil.copy(data / VIEW, outside)
    (data / VIEW).unlink()
    (data / VIEW).symlink_to(outside)
    code, _, err = export(capsys, fmt, str(data), str(tmp_path / "out"))
    assert code == 2 and len(err.splitlines()) == 1 and "points outside the dataset" in err
    assert not [p for p in (tmp_path / "out").rglob("*") if p.is_file() and p.read_bytes() == outside.read_bytes()]


def test_boxes_outside_the_image_are_cut_to_it_and_counted(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Case 6: a negative box went into COCO (area 14) and YOLO (negative width)."""
    path = data / "Single-Strawberry" / "000" / "annotations.json"
    annotations = json.loads(path.read_text())
    boxes = annotations["0001.jpeg"]["bounding_boxes"]
    boxes[0][:4] = [-5, -3, 9, 7]  # reaches over the top left corner
    boxes.append([70, 50, 4, 4, 99, 0])  # wholly outside the 64 x 48 image
    path.write_text(json.dumps(annotations))
    code, _, err = export(capsys, "coco", str(data), str(tmp_path / "coco"))
    assert code == 0 and "1 box(es) reaching outside their image were cut" in err and "1 with no pixel" in err
    coco = json.loads((tmp_path / "coco" / "annotations" / "instances_train.json").read_text())
    for entry in coco["annotations"]:
        x, y, w, h = entry["bbox"]
        assert x >= 0 and y >= 0 and w > 0 and h > 0 and x + w <= 64 and y + h <= 48
    assert export(capsys, "yolo", str(data), str(tmp_path / "yolo"))[0] == 0
    for label in (tmp_path / "yolo" / "labels").rglob("*.txt"):
        for line in label.read_text().splitlines():
            assert all(0 <= float(v) <= 1 for v in line.split()[1:]), line


def test_a_truncated_image_stops_the_export_before_it_is_copied(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Case 6: a truncated JPEG was copied into YOLO with exit 0."""
    image = data / VIEW
    image.write_bytes(image.read_bytes()[:-200])
    code, _, err = export(capsys, "yolo", str(data), str(tmp_path / "yolo"))
    assert code == 2 and len(err.splitlines()) == 1 and f"{image}: cannot decode" in err
    assert not list((tmp_path / "yolo").rglob("*_000_0001.jpeg"))


def test_a_renamed_scene_folder_is_refused_not_dropped(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Case 6: a scene folder renamed to an odd name gave a COCO train split of 0 images, exit 0."""
    (data / "Single-Strawberry" / "000").rename(data / "Single-Strawberry" / "000 (copy)")
    code, _, err = export(capsys, "coco", str(data), str(tmp_path / "coco"))
    assert code == 2 and len(err.splitlines()) == 1
    assert "Single-Strawberry/000" in err and "Single-Strawberry/000 (copy)" in err and "rename" in err


@pytest.mark.parametrize("fmt", ["coco", "yolo"])
def test_a_scene_that_lost_its_labels_is_refused_not_dropped(
    fmt: str, data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A scene whose annotations.json became a link to itself left the export, exit 0."""
    labels = data / "Single-Strawberry" / "001" / "annotations.json"
    labels.unlink()
    labels.symlink_to("annotations.json")
    code, _, err = export(capsys, fmt, str(data), str(tmp_path / "out"))
    assert code == 2 and len(err.splitlines()) == 1
    assert "Single-Strawberry/001: a" in err and "without a readable annotations.json" in err
    assert not (tmp_path / "out").exists()  # refused before anything is created


def test_a_killed_export_leaves_nothing_the_next_run_keeps(
    pristine: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Case 7: kill -9 during export coco left hidden working folders no later run removed; a
    stopped export is carried on by the same command, a finished one replaced only with --force."""
    out = tmp_path / "coco"
    (out / "annotations" / ".coco-k1ll3d").mkdir(parents=True)
    (out / "annotations" / ".coco-k1ll3d" / "images").write_text("[{")
    (out / "annotations" / ".instances_train.json.tmp").write_text("{")
    (out / ".davis_ag-export-unfinished").touch()
    assert export(capsys, "coco", str(pristine), str(out))[0] == 0
    assert sorted(p.name for p in out.rglob("*")) == ["annotations", "instances_test.json", "instances_train.json"]
    code, _, err = export(capsys, "coco", str(pristine), str(out))
    assert code == 2 and "already exists: give --force" in err
    assert export(capsys, "coco", str(pristine), str(out), "--force")[0] == 0


def test_a_full_disk_leaves_no_half_image_under_its_name(
    pristine: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Case 7: export yolo on a full disk left a truncated image under its final name and named the
    source image as where space ran out. Here links are impossible (another file system) and the
    disk fills after the first kilobyte of a copy."""
    import davis_ag.detection.yolo_export as yolo_export

    def no_links(source: object, target: object) -> None:
        raise OSError(errno.EXDEV, os.strerror(errno.EXDEV))

    def copy_until_full(source: object, target: object, *args: object) -> None:
        target.write(source.read(1024))
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(yolo_export.os, "link", no_links)
    monkeypatch.setattr(yolo_export.shutil, "copyfileobj", copy_until_full)
    out = tmp_path / "yolo"
    code, _, err = export(capsys, "yolo", str(pristine), str(out))
    assert code == 1 and len(err.splitlines()) == 1 and "No space left on device" in err
    target = err.split("error: ")[1].split(": cannot write")[0]
    assert target.startswith(str(out / "images")), err  # the file being written, not the source
    for image in (out / "images").rglob("*"):
        assert image.is_dir() or Image.open(image).load() is not None  # none half-written
    assert not list(out.rglob(".*.tmp"))


def test_an_export_is_never_two_exports_mixed(
    pristine: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--force refreshed a finished export in place, so the images of another dataset (or split)
    stayed beside the new ones, and a stopped export was carried on by any export into the
    folder: one scene id could land in train and in test."""
    other = write_tiny_dataset(tmp_path / "other", "sp", "strawberry", scenes=3, size=(64, 48), seed=5)
    out = tmp_path / "yolo"
    assert export(capsys, "yolo", str(other), str(out))[0] == 0
    three = sorted(p.name for p in out.rglob("*.jpeg"))
    assert export(capsys, "yolo", str(pristine), str(out), "--force")[0] == 0
    two = sorted(p.name for p in out.rglob("*.jpeg"))
    assert len(two) < len(three)  # the other dataset's images are gone, not kept beside
    fresh = tmp_path / "fresh"
    assert export(capsys, "yolo", str(pristine), str(fresh))[0] == 0
    assert two == sorted(p.name for p in fresh.rglob("*.jpeg"))
    # A stopped export is carried on by the same export only.
    from davis_ag.commands.export import export_settings

    stopped = export_settings(cli.build_parser().parse_args(["export", "yolo", str(other), str(out)]))
    (out / ".davis_ag-export-unfinished").write_text(json.dumps(stopped))  # as a killed run leaves it
    code, _, err = export(capsys, "yolo", str(pristine), str(out))
    assert code == 2 and "unfinished export of another dataset" in err and "--force" in err
    assert export(capsys, "yolo", str(other), str(out), "--split", "test")[0] == 2
    assert export(capsys, "yolo", str(pristine), str(out), "--force")[0] == 0
    assert not (out / ".davis_ag-export-unfinished").exists()


def test_a_segment_export_needs_every_mask(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A view without its _seg.png got box lines among the polygon lines: the export said it was
    done, and ultralytics refused to load it ("equal numbers of boxes and segments")."""
    from layout_factory import write_original_style_dataset

    data = write_original_style_dataset(tmp_path / "orig", scenes=2, missing_mask=True)
    code, _, err = export(capsys, "yolo", str(data), str(tmp_path / "seg"), "--task", "segment")
    assert code == 2 and "_seg.png: missing, and --task segment needs every view's instance mask" in err
    assert not (tmp_path / "seg").exists()  # refused before anything is made: no stopped export to trip on
    assert export(capsys, "yolo", str(data), str(tmp_path / "boxes"))[0] == 0  # boxes need no mask


@pytest.mark.parametrize("fmt", ["coco", "yolo"])
def test_a_scene_in_both_splits_is_never_exported_to_both(
    fmt: str, data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    splits = data / "splits.json"
    doc = json.loads(splits.read_text())
    doc["test"] = sorted({*doc["test"], doc["train"][0]})
    splits.write_text(json.dumps(doc))
    code, _, err = export(capsys, fmt, str(data), str(tmp_path / "out"))
    assert code == 2 and "in both train and test" in err
    assert not (tmp_path / "out").exists()
