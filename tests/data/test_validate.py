"""``davis-ag validate``: sound datasets pass, each kind of damage gives one clear line and exit 1."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from davis_ag import cli
from davis_ag.data.validate import validate_dataset
from davis_ag.formats.masks import mask_image
from davis_ag.scene.view_grid import views_per_scene
from layout_factory import tiny_specs, write_original_style_dataset, write_tiny_dataset
from wide_masks import widen_scene

SCENE = Path("Single-Strawberry") / "000"


@pytest.fixture(autouse=True)
def only_validate(monkeypatch: pytest.MonkeyPatch) -> None:
    # Other sub-commands may be mid-development; these tests exercise validate alone.
    assert "validate" in cli.COMMANDS
    monkeypatch.setattr(cli, "COMMANDS", ["validate"])


@pytest.fixture(scope="module")
def pristine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("pristine")
    write_tiny_dataset(root, "sp", "strawberry", scenes=3)
    write_tiny_dataset(root, "mp", "tomato", scenes=1)
    return root


@pytest.fixture
def dataset(pristine: Path, tmp_path: Path) -> Path:
    return Path(shutil.copytree(pristine, tmp_path / "ds"))


def run(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, list[str], str]:
    code = cli.main(["validate", *args])
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out.splitlines(), err


def edit_annotations(path: Path, change) -> None:  # type: ignore[no-untyped-def]
    data = json.loads(path.read_text())
    change(data)
    path.write_text(json.dumps(data))


def test_sound_dataset_passes(pristine: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, lines, _ = run(capsys, str(pristine))
    assert code == 0
    assert len(lines) == 1 and lines[0].startswith("checked 4 scenes, ") and lines[0].endswith(": sound")


def test_report_counts(pristine: Path) -> None:
    report = validate_dataset(pristine)
    ann = [json.loads(p.read_text()) for p in pristine.glob("*/*/annotations.json")]
    assert report.ok and report.scenes == 4
    assert report.views == sum(len(a) for a in ann)
    assert report.boxes == sum(len(e["bounding_boxes"]) for a in ann for e in a.values())


def test_original_style_passes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    write_original_style_dataset(tmp_path, "sp", "vine", scenes=1)
    (annotations,) = [json.loads(p.read_text()) for p in tmp_path.glob("*/*/annotations.json")]
    boxes = sum(len(entry["bounding_boxes"]) for entry in annotations.values())
    code, lines, _ = run(capsys, str(tmp_path))
    assert (code, lines[-1]) == (0, f"checked 1 scene, {len(annotations)} views, {boxes} boxes: sound")


def test_dangling_pointer(dataset: Path, capsys: pytest.CaptureFixture[str]) -> None:
    def dangle(data: dict) -> None:
        data["0002.jpeg"]["forward"] = "9999.jpeg"

    edit_annotations(dataset / SCENE / "annotations.json", dangle)
    for quick in ([], ["--quick"]):
        code, lines, _ = run(capsys, str(dataset), *quick)
        assert code == 1
        assert lines[:-1] == [
            f"{dataset / SCENE / 'annotations.json'}: 0002.jpeg: forward points to "
            "9999.jpeg, which is not a view of this scene"
        ]
        assert lines[-1].endswith(": 1 problem")


def test_box_disagreeing_with_mask(dataset: Path, capsys: pytest.CaptureFixture[str]) -> None:
    def widen(data: dict) -> None:
        data["0003.jpeg"]["bounding_boxes"][0][2] += 3

    edit_annotations(dataset / SCENE / "annotations.json", widen)
    code, lines, _ = run(capsys, str(dataset / "Single-Strawberry"))
    assert code == 1 and len(lines) == 2
    assert lines[0].startswith(f"{dataset / SCENE / 'images' / '0003_seg.png'}: 0003.jpeg: box of fruit ")
    assert "but its mask pixels span" in lines[0]
    # Pixel checks are what --quick leaves out.
    code, lines, _ = run(capsys, str(dataset), "--quick")
    assert code == 0
    # A box one pixel off passes only with slack.
    code, _, _ = run(capsys, str(dataset / SCENE), "--box-tolerance", "3")
    assert code == 0


def test_mask_with_fruit_lacking_a_box(dataset: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = dataset / SCENE / "images" / "0004_seg.png"
    mask = np.asarray(Image.open(path)).copy()
    mask[0, 0] = 200
    Image.fromarray(mask).save(path)
    code, lines, _ = run(capsys, str(dataset))
    assert code == 1 and lines[0] == f"{path}: holds fruit 200, which has no box in 0004.jpeg"


def test_missing_image_and_mask(dataset: Path, capsys: pytest.CaptureFixture[str]) -> None:
    images = dataset / SCENE / "images"
    (images / "0005.jpeg").unlink()
    (images / "0006_seg.png").unlink()
    code, lines, _ = run(capsys, str(dataset))
    assert code == 1
    assert lines[:-1] == [
        f"{images / '0005.jpeg'}: missing: annotations.json has an entry 0005.jpeg for it",
        f"{images / '0006_seg.png'}: missing: the instance mask of 0006.jpeg",
    ]


def test_malformed_json(dataset: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = dataset / SCENE / "annotations.json"
    path.write_text(path.read_text()[:200])
    code, lines, err = run(capsys, str(dataset))
    assert code == 1 and err == ""
    assert len(lines) == 2 and lines[0].startswith(f"{path}: not valid JSON (line ")
    assert lines[1].endswith(": 1 problem")


def test_schema_problems_each_reported(dataset: Path, capsys: pytest.CaptureFixture[str]) -> None:
    def break_schema(data: dict) -> None:
        data["0001.jpeg"]["bounding_boxes"] = [[1, 2, 3]]
        data["0002.jpeg"]["pose"] = "up"
        data["0003.jpeg"] = []
        data["0004.jpeg"]["bounding_boxes"].append(data["0004.jpeg"]["bounding_boxes"][0])

    edit_annotations(dataset / SCENE / "annotations.json", break_schema)
    code, lines, _ = run(capsys, str(dataset), "--quick")
    reasons = [line.split("annotations.json: ", 1)[1] for line in lines[:-1]]
    assert code == 1 and len(reasons) == 4
    assert reasons[0].startswith("entry '0001.jpeg': a box must be")
    assert reasons[1].startswith("entry '0002.jpeg': pose must be")
    assert reasons[2] == "entry '0003.jpeg': entry must be an object, got list"
    assert reasons[3].endswith("has two boxes in this view")


def test_orphan_image_splits_and_counts(dataset: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scene = dataset / "Single-Strawberry" / "002"
    last = sorted((scene / "images").glob("*.jpeg"))[-1]

    def drop_last(data: dict) -> None:
        del data[last.name]
        for entry in data.values():
            entry.update({k: "" for k, v in entry.items() if v == last.name})

    edit_annotations(scene / "annotations.json", drop_last)
    splits = json.loads((dataset / "splits.json").read_text())
    splits["test"].append("Single-Strawberry/000")
    splits["train"].append("Single-Tomato/007")
    (dataset / "splits.json").write_text(json.dumps(splits))
    code, lines, _ = run(capsys, str(dataset), "--quick")
    views = views_per_scene(*tiny_specs("sp", "strawberry"))  # the factory's grid
    assert code == 1
    assert lines[:-1] == [
        f"{dataset / 'splits.json'}: train lists Single-Tomato/007, which is not a scene here",
        f"{dataset / 'splits.json'}: 1 scene(s) in both train and test, e.g. Single-Strawberry/000",
        f"{last}: has no entry in annotations.json",
        f"{last.with_name(last.stem + '_seg.png')}: has no entry in annotations.json",
        f"{scene / 'annotations.json'}: has {views - 1} views but 2 of the 3 scenes of Single-Strawberry have {views}",
    ]


def test_a_group_answers_for_its_own_split_entries(dataset: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # A group validated alone neither sees nor blames another group's entries; the whole dataset does.
    splits = json.loads((dataset / "splits.json").read_text())
    tomato = next(i for i in splits["train"] + splits["test"] if i.startswith("Multi-Tomato"))
    splits["train"].append(tomato)
    splits["test"].append(tomato)
    (dataset / "splits.json").write_text(json.dumps(splits))
    code, lines, _ = run(capsys, str(dataset / "Single-Strawberry"), "--quick")
    assert code == 0 and lines[-1].endswith(": sound")
    code, lines, _ = run(capsys, str(dataset), "--quick")
    assert code == 1 and lines[0] == f"{dataset / 'splits.json'}: 1 scene(s) in both train and test, e.g. {tomato}"


def test_wrong_mask_mode_and_size(dataset: Path, capsys: pytest.CaptureFixture[str]) -> None:
    images = dataset / SCENE / "images"
    Image.open(images / "0001_seg.png").convert("RGB").save(images / "0001_seg.png")
    Image.new("L", (10, 10), 255).save(images / "0002_seg.png")
    (images / "0003.jpeg").write_bytes((images / "0003.jpeg").read_bytes()[:300])
    code, lines, _ = run(capsys, str(dataset / SCENE))
    assert code == 1
    assert lines[0] == f"{images / '0001_seg.png'}: must be a uint8 or uint16 single-channel PNG, got mode RGB"
    assert lines[1] == f"{images / '0002_seg.png'}: is 10x10 but its image is 128x72"
    assert lines[2].startswith(f"{images / '0003.jpeg'}: cannot decode (")


def test_a_scene_of_more_than_255_fruit_with_16_bit_masks_is_sound(
    dataset: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    widen_scene(dataset / SCENE)  # fruit ids 300 and up, uint16 masks, 306 fruit in scene.json
    code, lines, _ = run(capsys, str(dataset / SCENE))
    assert code == 0 and len(lines) == 1 and lines[0].endswith(": sound")
    mask = np.asarray(Image.open(dataset / SCENE / "images" / "0001_seg.png"))
    assert mask.dtype == np.uint16 and mask.max() == 65535 and 300 <= mask[mask != 65535].min()


def test_a_mask_of_the_wrong_type_for_the_fruit_count_is_refused(
    dataset: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    images = dataset / SCENE / "images"
    mask = np.asarray(Image.open(images / "0001_seg.png"))
    mask_image(np.where(mask == 255, 65535, mask.astype(np.uint16)).astype(np.uint16)).save(images / "0001_seg.png")
    fruit = len(json.loads((dataset / SCENE / "scene.json").read_text())["fruits"])
    code, lines, _ = run(capsys, str(dataset / SCENE))
    assert code == 1 and lines[:-1] == [
        f"{images / '0001_seg.png'}: is uint16 but scene.json records {fruit} fruit, whose masks are uint8 (255 = no fruit)"
    ]
    # The other way round, and a box naming a fruit id a uint8 mask cannot hold.
    widen_scene(dataset / SCENE.parent / "001")
    wide = dataset / SCENE.parent / "001" / "images"
    mask = np.asarray(Image.open(wide / "0002_seg.png"))
    Image.fromarray(np.where(mask == 65535, 255, mask % 256).astype(np.uint8), mode="L").save(wide / "0002_seg.png")
    edit_annotations(
        dataset / SCENE / "annotations.json",
        lambda data: data["0003.jpeg"]["bounding_boxes"].append([0, 0, 1, 1, 300, 0]),
    )
    code, lines, _ = run(capsys, str(dataset / SCENE.parent))
    assert (
        f"{dataset / SCENE / 'annotations.json'}: 0003.jpeg: box [0, 0, 1, 1, 300]: fruit id must be 0..254 to fit the uint8 mask"
        in lines
    )
    assert any(line.startswith(f"{wide / '0002_seg.png'}: is uint8 but scene.json records ") for line in lines)


def test_not_a_dataset(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, lines, err = run(capsys, str(tmp_path))
    assert code == 2 and lines == []
    assert err.count("\n") == 1 and "not a DAVIS-Ag dataset" in err and err.startswith("davis-ag validate: error:")


def test_relative_paths_print_relative(
    dataset: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    (dataset / SCENE / "images" / "0007.jpeg").unlink()
    monkeypatch.chdir(dataset)
    code, lines, _ = run(capsys, ".")
    assert code == 1 and lines[0].startswith(str(SCENE / "images" / "0007.jpeg") + ": missing")


def test_a_pool_of_processes_reports_what_one_process_does(
    dataset: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--workers``: damage in two scenes is reported the same, line for line and in the same
    order, by one process and by a pool (forced on this small dataset)."""
    from davis_ag.data import validate_pool

    edit_annotations(dataset / SCENE / "annotations.json", lambda d: d["0002.jpeg"].update(forward="9999.jpeg"))
    mask = next((dataset / "Single-Strawberry" / "001" / "images").glob("*_seg.png"))
    mask.write_bytes(mask.read_bytes()[:40])
    one = run(capsys, str(dataset), "--workers", "1")
    monkeypatch.setattr(validate_pool, "POOL_FROM_BYTES", 0)
    pooled = run(capsys, str(dataset), "--workers", "2")
    assert one[0] == pooled[0] == 1
    assert one[1] == pooled[1] and any("cannot decode" in line for line in one[1])


@pytest.mark.parametrize("loss", ["deleted", "a folder"])
def test_a_scene_that_lost_its_labels_is_not_passed_over(
    loss: str, dataset: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The reader skips a folder without annotations.json, so validate said "sound" (exit 0) with a
    scene gone; with splits.json it only said the split names a scene that is not there."""
    path = dataset / SCENE / "annotations.json"
    path.unlink()
    if loss == "a folder":
        path.mkdir()
    (dataset / "splits.json").unlink()
    code, lines, _ = run(capsys, str(dataset))
    what = "missing" if loss == "deleted" else "a folder"
    assert code == 1 and f"{path}: {what}: this scene has images but no labels" in lines[0]
    # The whole group lost: a group folder with no scene the reader found is still looked at.
    for scene in (dataset / "Multi-Tomato").iterdir():
        (scene / "annotations.json").unlink()
    code, lines, _ = run(capsys, str(dataset))
    assert code == 1 and any("Multi-Tomato/000/annotations.json: missing" in line for line in lines)
