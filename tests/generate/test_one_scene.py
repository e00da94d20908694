"""Generating a scene end to end (tiny images, a reduced grid) and the generate command's refusals."""

from __future__ import annotations

import json
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from davis_ag import cli
from davis_ag.data.reader import open_dataset
from davis_ag.data.validate import validate_dataset
from davis_ag.errors import UserError
from davis_ag.formats.layout import ROOT_FILES
from davis_ag.formats.scene_file import read_scene_file
from davis_ag.generate.one_scene import SceneRequest, generate_scene
from davis_ag.scene.camera import Camera
from davis_ag.scene.plants import Phenotype, in_table_range, require_native_helios
from davis_ag.scene.specs import CROPS, SCENARIOS, SP_ACTIONS

#: Single-plant strawberry on a 3 m x 1 m grid with 50 cm steps at two altitudes: three rows of
#: the staggered lattice, 11 positions outside the 0.75 m exclusion zone on either side of the
#: plant, 22 views, so every kind of move is valid somewhere and blocked somewhere (grid edge or
#: exclusion zone).
SCENARIO = replace(SCENARIOS["sp"], extent=(3.0, 1.0), step=0.5, altitude_levels=(0, 1))
CAMERA = Camera(96, 54)
REQUEST = SceneRequest(SCENARIO, CROPS["strawberry"], index=0, dataset_seed=0, camera=CAMERA)
VIEWS = 22


@pytest.fixture(scope="module")
def generated(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, dict]:
    """The dataset root, the scene folder and the timing statistics of one generated scene."""
    root = tmp_path_factory.mktemp("dataset")
    calls: list[tuple[int, int]] = []
    scene_dir, stats = generate_scene(REQUEST, root, on_view=lambda done, total: calls.append((done, total)))
    assert calls == [(i, VIEWS) for i in range(1, VIEWS + 1)]
    return root, scene_dir, stats


def test_generated_scene_is_a_sound_dataset(generated: tuple[Path, Path, dict]) -> None:
    root, scene_dir, stats = generated
    assert scene_dir == root / "Single-Strawberry" / "000"
    assert stats["views"] == VIEWS
    # Published atomically: the scene folder and nothing half-written beside it.
    assert sorted(p.name for p in scene_dir.parent.iterdir()) == ["000"]
    assert sorted(p.name for p in scene_dir.iterdir()) == ["annotations.json", "images", "scene.json"]
    names = [f"{i:04d}.jpeg" for i in range(1, VIEWS + 1)]
    assert sorted(p.name for p in (scene_dir / "images").iterdir()) == sorted(
        names + [n.replace(".jpeg", suffix) for n in names for suffix in ("_seg.png", "_depth.png", "_class.png")]
    )

    report = validate_dataset(root)
    assert report.ok, [str(p) for p in report.problems]
    assert report.summary().endswith(": sound") and (report.scenes, report.views) == (1, VIEWS)

    dataset = open_dataset(root)
    (scene,) = dataset.scenes
    assert (scene.scenario, scene.crop, len(scene)) == ("sp", "strawberry", VIEWS)
    view = scene.view("0001.jpeg")
    assert view.image().shape == (CAMERA.height, CAMERA.width, 3)
    assert view.mask().shape == (CAMERA.height, CAMERA.width)


def test_annotations_follow_the_published_layout(generated: tuple[Path, Path, dict]) -> None:
    _, scene_dir, _ = generated
    annotations = json.loads((scene_dir / "annotations.json").read_text())
    assert list(annotations) == [f"{i:04d}.jpeg" for i in range(1, VIEWS + 1)]
    boxes = 0
    for action in SP_ACTIONS:
        assert {entry[action] == "" for entry in annotations.values()} == {True, False}, action
    for name, entry in annotations.items():
        assert set(entry) == {"bounding_boxes", "pose", *SP_ACTIONS}
        assert len(entry["pose"]) == 5
        for action in SP_ACTIONS:
            assert entry[action] == "" or entry[action] in annotations
        mask = np.asarray(Image.open(scene_dir / "images" / name.replace(".jpeg", "_seg.png")))
        assert mask.dtype == np.uint8 and mask.shape == (CAMERA.height, CAMERA.width)
        boxed = {box[4] for box in entry["bounding_boxes"]}
        assert set(np.unique(mask)) <= boxed | {255}
        for x, y, w, h, fruit_id, zero in entry["bounding_boxes"]:
            rows, cols = np.nonzero(mask == fruit_id)
            assert [x, y, x + w - 1, y + h - 1, zero] == [cols.min(), rows.min(), cols.max(), rows.max(), 0]
        boxes += len(boxed)
    assert boxes > 0  # the plant's fruit are seen


def test_scene_json_records_what_the_annotations_leave_out(generated: tuple[Path, Path, dict]) -> None:
    _, scene_dir, _ = generated
    meta = json.loads((scene_dir / "scene.json").read_text())
    annotations = json.loads((scene_dir / "annotations.json").read_text())
    # Written through its model and read back through it unchanged, key order included.
    assert json.dumps(read_scene_file(scene_dir / "scene.json").as_written()) == json.dumps(meta)
    assert meta["seed"] == REQUEST.seed and meta["dataset_seed"] == 0
    assert (meta["scenario"], meta["crop"], meta["scene"]) == ("sp", "strawberry", "Single-Strawberry/000")
    assert meta["camera"] == CAMERA.intrinsics()
    assert meta["grid"]["views"] == VIEWS and meta["grid"]["altitudes_m"] == [0.25, 0.40]
    # Section III-C: 210 px for a strawberry at the paper's 1280x720, scaled by the image area.
    assert meta["min_fruit_pixels"] == max(1, round(210 * 96 * 54 / (1280 * 720)))

    crop = CROPS["strawberry"]
    (plant,) = meta["plants"]
    # Table 1 +- the paper's spread, up to the tolerance the plant is grown to (plants.TOLERANCE).
    assert in_table_range(Phenotype(**plant["phenotype_measured"]), crop, slack=0.04)
    assert plant["fruit_count"] >= crop.min_fruit
    fruits = meta["fruits"]
    assert [f["id"] for f in fruits] == list(range(len(fruits))) and len(fruits) == plant["fruit_count"]
    for fruit in fruits:
        assert len(fruit["center"]) == 3 and len(fruit["size"]) == 3
        assert 0 < fruit["center"][2] < plant["phenotype_measured"]["plant_height"]
        assert max(fruit["size"]) < 4 * crop.fruit_radius

    assert list(meta["visible_fraction"]) == list(annotations)
    for name, fractions in meta["visible_fraction"].items():
        assert set(fractions) == {str(box[4]) for box in annotations[name]["bounding_boxes"]}
        assert all(0 < value <= 1 for value in fractions.values())


def test_the_same_request_gives_the_same_scene(generated: tuple[Path, Path, dict], tmp_path: Path) -> None:
    _, first, _ = generated
    second, _ = generate_scene(REQUEST, tmp_path)
    assert (first / "annotations.json").read_bytes() == (second / "annotations.json").read_bytes()
    meta = [json.loads((d / "scene.json").read_text()) for d in (first, second)]
    for m in meta:
        del m["timing_s"]
    assert meta[0] == meta[1]
    for mask in sorted((first / "images").glob("*_seg.png")):
        assert mask.read_bytes() == (second / "images" / mask.name).read_bytes(), mask.name
    # Colour images come from the same draws too (Mesa's software rasteriser is deterministic).
    for image in sorted((first / "images").glob("*.jpeg")):
        assert image.read_bytes() == (second / "images" / image.name).read_bytes(), image.name


def same_scene(first: Path, second: Path) -> None:
    """Two scene folders hold the same files with the same bytes (scene.json: but its timings)."""
    assert (first / "annotations.json").read_bytes() == (second / "annotations.json").read_bytes()
    meta = [json.loads((d / "scene.json").read_text()) for d in (first, second)]
    for m in meta:
        del m["timing_s"]
    assert meta[0] == meta[1]
    assert sorted(p.name for p in first.rglob("*")) == sorted(p.name for p in second.rglob("*"))
    for image in sorted((first / "images").iterdir()):
        assert image.read_bytes() == (second / "images" / image.name).read_bytes(), image.name


def test_a_scene_stopped_mid_way_resumes_to_the_same_scene(generated: tuple[Path, Path, dict], tmp_path: Path) -> None:
    def stop_after_9(done: int, total: int) -> None:
        if done == 9:
            raise KeyboardInterrupt  # Ctrl-C; a kill -9 leaves the same folder without a word

    with pytest.raises(KeyboardInterrupt):
        generate_scene(REQUEST, tmp_path, on_view=stop_after_9)
    partial = tmp_path / "Single-Strawberry" / ".000.partial"
    assert not (tmp_path / REQUEST.folder).exists() and partial.is_dir()
    drawn: list[int] = []
    scene_dir, _ = generate_scene(REQUEST, tmp_path, on_view=lambda done, total: drawn.append(done))
    assert drawn == list(range(1, VIEWS + 1)) and not partial.exists()
    # The views written before the stop were kept, not drawn again.
    assert json.loads((scene_dir / "scene.json").read_text())["timing_s"]["views_from_an_earlier_run"] == 9
    same_scene(generated[1], scene_dir)


def test_a_view_cut_short_and_those_after_it_are_drawn_again(
    generated: tuple[Path, Path, dict], tmp_path: Path
) -> None:
    def stop_after_9(done: int, total: int) -> None:
        if done == 9:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        generate_scene(REQUEST, tmp_path, on_view=stop_after_9)
    cut = tmp_path / "Single-Strawberry" / ".000.partial" / "images" / "0005_seg.png"
    cut.write_bytes(cut.read_bytes()[:-20])  # what a power loss can leave of a file
    scene_dir, _ = generate_scene(REQUEST, tmp_path)
    assert json.loads((scene_dir / "scene.json").read_text())["timing_s"]["views_from_an_earlier_run"] == 4
    same_scene(generated[1], scene_dir)


def test_a_journal_with_a_gap_keeps_only_the_views_before_it(
    generated: tuple[Path, Path, dict], tmp_path: Path
) -> None:
    """A stop while a view's files were awaited dropped that view from the queue unjournalled and
    journalled the views after it; the resumed scene drew it last, out of order."""

    def stop_after_9(done: int, total: int) -> None:
        if done == 9:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        generate_scene(REQUEST, tmp_path, on_view=stop_after_9)
    journal = tmp_path / "Single-Strawberry" / ".000.partial" / "views.jsonl"
    lines = journal.read_text().splitlines()
    journal.write_text("\n".join(lines[:2] + lines[3:]) + "\n")  # view 0003 missing, 0004... follow
    scene_dir, _ = generate_scene(REQUEST, tmp_path)
    assert json.loads((scene_dir / "scene.json").read_text())["timing_s"]["views_from_an_earlier_run"] == 2
    same_scene(generated[1], scene_dir)  # annotations.json's keys in the uninterrupted order too


def test_a_stop_while_the_scene_is_published_keeps_every_view(
    generated: tuple[Path, Path, dict], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The journal was removed before annotations.json and scene.json were written: a kill in
    between left a folder with no key, and the next run drew the whole scene again."""
    import davis_ag.generate.scene_writer as scene_writer

    def killed_at_publish(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(scene_writer, "_fsync_dir", killed_at_publish)  # after the JSON, before the rename
    with pytest.raises(KeyboardInterrupt):
        generate_scene(REQUEST, tmp_path)
    monkeypatch.undo()
    scene_dir, _ = generate_scene(REQUEST, tmp_path)
    assert json.loads((scene_dir / "scene.json").read_text())["timing_s"]["views_from_an_earlier_run"] == VIEWS
    same_scene(generated[1], scene_dir)


def test_a_partial_scene_of_another_request_is_cleared(generated: tuple[Path, Path, dict], tmp_path: Path) -> None:
    partial = tmp_path / "Single-Strawberry" / ".000.partial"
    (partial / "images").mkdir(parents=True)
    (partial / "resume.json").write_text(json.dumps({"request": "another one"}))
    (partial / "views.jsonl").write_text(
        json.dumps({"name": "0001.jpeg", "entry": {}, "extras": {}, "files": ["0001.jpeg"]}) + "\n"
    )
    (partial / "images" / "0001.jpeg").write_bytes(b"not this scene's view")
    scene_dir, _ = generate_scene(REQUEST, tmp_path)
    assert json.loads((scene_dir / "scene.json").read_text())["timing_s"]["views_from_an_earlier_run"] == 0
    same_scene(generated[1], scene_dir)


# ---------------------------------------------------------------------------------------------
# The command line


@pytest.fixture(autouse=True)
def only_generate(monkeypatch: pytest.MonkeyPatch) -> None:
    # Other sub-commands may be mid-development; these tests exercise generate alone.
    assert "generate" in cli.COMMANDS
    monkeypatch.setattr(cli, "COMMANDS", ["generate"])


def refused(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    """Run ``davis-ag generate`` expecting a refusal: exit status 2, one line on stderr, returned."""
    try:
        code = cli.main(["generate", *args])
    except SystemExit as exit_:  # argparse's own refusals
        code = exit_.code
    out, err = capsys.readouterr()
    assert code == 2, (out, err)
    assert "Traceback" not in out + err
    lines = err.splitlines()
    assert len(lines) == 1, err
    return lines[0]


def snapshot(folder: Path) -> dict[str, bytes | None]:
    return {str(p.relative_to(folder)): p.read_bytes() if p.is_file() else None for p in sorted(folder.rglob("*"))}


def test_unknown_crop_and_scenario_are_refused(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    assert "banana" in refused(capsys, "--crop", "banana", "--out", str(tmp_path / "ds"))
    assert "sideways" in refused(capsys, "--scenario", "sideways", "--out", str(tmp_path / "ds"))
    assert not (tmp_path / "ds").exists()


@pytest.mark.parametrize(
    "args",
    [
        ["--scenes", "0"],
        ["--scenes", "-3"],
        ["--scenes", "two"],
        ["--size", "garbage"],
        ["--size", "1280x"],
        ["--size", "8x8"],
        ["--seed", "-1"],
        ["--first", "999", "--scenes", "2"],
    ],
)
def test_bad_numbers_are_refused(args: list[str], capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    line = refused(capsys, *args, "--out", str(tmp_path / "ds"))
    assert line.startswith("davis-ag generate: ")
    assert not (tmp_path / "ds").exists()


def test_an_out_that_is_a_file_is_refused(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    out = tmp_path / "notes.txt"
    out.write_text("mine")
    assert "is a file" in refused(capsys, "--out", str(out), "--size", "96x54")
    assert out.read_text() == "mine"


def test_an_out_holding_other_things_is_left_alone(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    out = tmp_path / "home"
    (out / "photos").mkdir(parents=True)
    (out / "photos" / "cat.jpeg").write_bytes(b"\xff\xd8 not really")
    (out / "todo.txt").write_text("buy soil")
    before = snapshot(out)
    assert "holds other things" in refused(capsys, "--out", str(out), "--size", "96x54")
    assert snapshot(out) == before


def test_a_scene_made_with_another_seed_is_not_overwritten(
    generated: tuple[Path, Path, dict],
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
) -> None:
    _, scene_dir, _ = generated
    root = tmp_path / "ds"
    shutil.copytree(scene_dir, root / "Single-Strawberry" / "000")
    before = snapshot(root / "Single-Strawberry")
    # Our scene was made with dataset seed 0; seed 1 would make another scene 000.
    line = refused(capsys, "--out", str(root), "--seed", "1", "--size", "96x54")
    assert "already holds a scene made with other settings" in line
    assert snapshot(root / "Single-Strawberry") == before
    assert {p.name for p in root.iterdir()} <= {"Single-Strawberry", *ROOT_FILES}


@pytest.mark.parametrize(
    "asked, said",
    [
        (["--no-depth"], "made with depth images, this run asks without: drop --no-depth"),
        (["--antialiasing", "msaa"], "drawn with antialiasing fxaa, not msaa: use --antialiasing fxaa"),
    ],
)
def test_a_resumed_run_adds_no_scene_drawn_otherwise(
    asked: list[str],
    said: str,
    generated: tuple[Path, Path, dict],
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
) -> None:
    """dataset.json does not hold the depth choice or the antialiasing: a resumed run with
    another choice skipped the finished scene as complete and added scenes without depth (or
    drawn otherwise) beside it."""
    _, scene_dir, _ = generated
    root = tmp_path / "ds"
    shutil.copytree(scene_dir, root / "Single-Strawberry" / "000")
    before = snapshot(root / "Single-Strawberry")
    line = refused(capsys, "--out", str(root), "--scenes", "2", "--size", "96x54", *asked)
    assert said in line and str(root / "Single-Strawberry" / "000") in line
    assert snapshot(root / "Single-Strawberry") == before  # nothing added beside it
    # A run that asks only for other scenes (--first) is held to the finished ones too.
    line = refused(capsys, "--out", str(root), "--first", "1", "--scenes", "1", "--size", "96x54", *asked)
    assert said in line
    assert snapshot(root / "Single-Strawberry") == before


def test_mock_pyhelios_is_a_clear_error(monkeypatch: pytest.MonkeyPatch) -> None:
    import pyhelios.plugins

    from davis_ag.scene.build import build_scene

    # Without its native library (no system libGL/libEGL) pyhelios would silently run as a mock.
    monkeypatch.setattr(pyhelios.plugins, "get_library_info", lambda: {"is_mock": True, "library_path": None})
    with pytest.raises(UserError, match=r"mock mode.*libgl1"):
        require_native_helios()
    with pytest.raises(UserError, match="mock mode"):
        build_scene(SCENARIO, CROPS["strawberry"], np.random.default_rng(0))


def test_generate_command_refuses_mock_helios_before_any_scene(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import pyhelios.plugins

    monkeypatch.setattr(pyhelios.plugins, "get_library_info", lambda: {"is_mock": True, "library_path": None})
    out = tmp_path / "data"
    code = cli.main(["generate", "--scenes", "1", "--out", str(out), "--workers", "1"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "mock mode" in err[0]
    assert not out.exists()


def test_depth_images_are_written_read_and_checked(generated: tuple[Path, Path, dict], tmp_path: Path) -> None:
    root, scene_dir, _ = generated
    meta = json.loads((scene_dir / "scene.json").read_text())
    assert meta["renderer"]["name"] == "opengl" and meta["renderer"]["look"] == "default"
    assert meta["depth"]["unit"] == "mm" and meta["depth"]["no_hit"] == 0
    (scene,) = open_dataset(root).scenes
    fruits = {f["id"]: np.array(f["center"]) for f in meta["fruits"]}
    checked = 0
    for view in scene:
        depth, mask = view.depth(), view.mask()
        raw = np.asarray(Image.open(view.depth_path))
        assert raw.dtype == np.uint16 and depth.dtype == np.float32 and depth.shape == (CAMERA.height, CAMERA.width)
        assert (depth[0] == 0).all() and depth.max() > 0  # sky on the top row, ground below
        x, y, z, yaw, pitch = view.pose
        forward = np.array(
            [
                np.cos(np.radians(pitch)) * np.cos(np.radians(yaw)),
                np.cos(np.radians(pitch)) * np.sin(np.radians(yaw)),
                np.sin(np.radians(pitch)),
            ]
        )
        for box in view.boxes:
            seen = np.median(depth[mask == box.fruit_id])
            assert abs(seen - (fruits[box.fruit_id] - (x, y, z)) @ forward) < 0.05
            checked += 1
    assert checked > 0

    # Without depth (the original download, --no-depth) a scene still reads and validates.
    copy = tmp_path / "copy"
    shutil.copytree(root, copy)
    copied = copy / scene_dir.relative_to(root)
    for path in (copied / "images").glob("*_depth.png"):
        path.unlink()
    meta["depth"] = None
    (copied / "scene.json").write_text(json.dumps(meta))
    assert all(view.depth() is None for view in open_dataset(copy).scenes[0])
    assert validate_dataset(copy).ok

    # Depth that disagrees with the fruit's 3-D centres, or has the wrong size, is reported.
    first = copied / "images" / "0001_depth.png"
    doubled = np.clip(np.asarray(Image.open(scene_dir / "images" / "0001_depth.png")).astype(np.int64) * 2, 0, 65535)
    Image.fromarray(doubled.astype(np.uint16)).save(first)
    Image.fromarray(np.ones((10, 10), np.uint16) * 500).save(copied / "images" / "0002_depth.png")
    problems = [str(p) for p in validate_dataset(copy).problems]
    assert any("0002_depth.png" in p and "10x10" in p for p in problems)
    has_boxes = bool(scene.view("0001.jpeg").boxes)
    assert any("0001_depth.png" in p and "centre" in p for p in problems) == has_boxes


def test_depth_and_renderer_settings_flow_from_flags_and_configs() -> None:
    from davis_ag.generate.run_config import parse_dataset_config, single_group_config

    config = single_group_config("sp", "strawberry", 1, 0, 0, (96, 54), "helios", None, depth=False)
    (request,) = config.requests()
    assert (request.renderer, request.look, request.depth) == ("helios", "helios", False)
    text = (
        "renderer: opengl\nlook: helios\ndepth: false\nantialiasing: 1\n"
        "groups: [{scenario: sp, crop: tomato, scenes: 1}]\n"
    )
    (request,) = parse_dataset_config(text, "test").requests()
    assert (request.renderer, request.look, request.depth, request.antialiasing) == ("opengl", "helios", False, "none")
    with pytest.raises(UserError, match="antialiasing"):
        parse_dataset_config("antialiasing: 2\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n", "test")
    with pytest.raises(UserError, match="look"):
        parse_dataset_config("look: blocky\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n", "test")
    with pytest.raises(UserError, match="helios look"):
        single_group_config("sp", "strawberry", 1, 0, 0, (96, 54), "helios", "default")


def test_organ_classes_come_from_the_same_pass_as_the_masks(generated: tuple[Path, Path, dict], tmp_path: Path) -> None:
    from davis_ag.scene.organs import BARE_ORGAN_NAMES, FRUIT, LEAF, ORGAN_NAMES, SKY, SOIL, STEM

    root, scene_dir, _ = generated
    from davis_ag.generate.dataset_files import dataset_settings

    assert [c["name"] for c in dataset_settings([REQUEST])["classes"]] == list(ORGAN_NAMES)
    # A scene without a structure records the table of before (no class ``structure``).
    assert json.loads((scene_dir / "scene.json").read_text())["classes"]["table"] == list(BARE_ORGAN_NAMES)
    (scene,) = open_dataset(root).scenes
    seen: set[int] = set()
    for view in scene:
        classes, mask, depth = view.classes(), view.mask(), view.depth()
        assert classes.dtype == np.uint8 and classes.shape == (CAMERA.height, CAMERA.width)
        assert (classes[mask != 255] == FRUIT).all()  # every fruit pixel of the instance mask
        assert ((classes == SKY) == (depth == 0)).all()  # nothing hit: sky, in both images
        seen |= set(np.unique(classes).tolist())
    assert {SKY, SOIL, FRUIT, LEAF, STEM} <= seen

    # Class images lost from a scene whose scene.json records them are reported, one line each; a
    # scene without them (the original layout, older datasets) still reads and validates; a class
    # image that calls fruit pixels leaves is reported.
    copy = tmp_path / "copy"
    shutil.copytree(root, copy)
    images = copy / scene_dir.relative_to(root) / "images"
    boxed = next(v for v in scene if v.boxes)
    for path in images.glob("*_class.png"):
        if path.name != boxed.class_path.name:
            path.unlink()
    assert all(v.classes() is None for v in open_dataset(copy).scenes[0] if v.name != boxed.name)
    lost = [str(p) for p in validate_dataset(copy).problems]
    assert len(lost) == VIEWS - 1 and all("_class.png" in p and "records organ class images" in p for p in lost)
    meta_path = copy / scene_dir.relative_to(root) / "scene.json"
    meta_path.write_text(json.dumps({**json.loads(meta_path.read_text()), "classes": None}))
    assert validate_dataset(copy).ok
    wrong = np.where(boxed.mask() != 255, LEAF, boxed.classes()).astype(np.uint8)
    Image.fromarray(wrong, mode="L").save(images / boxed.class_path.name)
    problems = [str(p) for p in validate_dataset(copy).problems]
    assert len(problems) == 1 and boxed.class_path.name in problems[0] and "not class 2 (fruit)" in problems[0]


def test_each_fruits_points_lie_around_its_centre(generated: tuple[Path, Path, dict], tmp_path: Path) -> None:
    from davis_ag.data.point_cloud import export_point_clouds, read_ply

    root, scene_dir, _ = generated
    meta = json.loads((scene_dir / "scene.json").read_text())
    out = tmp_path / "clouds"
    assert export_point_clouds(root, out, fuse=True)["files"] == 1
    points = read_ply(out / "Single-Strawberry" / "000.ply")
    xyz = np.stack([points["x"], points["y"], points["z"]], axis=1).astype(np.float64)
    checked = 0
    for fruit in meta["fruits"]:
        mine = points["fruit_id"] == fruit["id"]
        if not mine.any():
            continue
        # Within the fruit's bounding sphere, give or take the depth image's millimetre steps.
        reach = np.linalg.norm(fruit["size"]) / 2 + 0.003
        assert np.linalg.norm(xyz[mine] - fruit["center"], axis=1).max() < reach, fruit["id"]
        assert (points["organ"][mine] == 2).all()
        checked += 1
    assert checked >= 1 and (points["organ"] == 1).any()
    assert export_point_clouds(root, out, max_depth=5.0)["files"] == VIEWS  # per view, beside the fused cloud
    assert len(list((out / "Single-Strawberry" / "000").glob("*.ply"))) == VIEWS


def test_random_appearance_changes_the_pictures_not_the_labels(
    generated: tuple[Path, Path, dict], tmp_path: Path
) -> None:
    _, paper_dir, _ = generated
    random_dir, _ = generate_scene(replace(REQUEST, appearance="random"), tmp_path)
    meta = json.loads((random_dir / "scene.json").read_text())
    assert meta["appearance"]["mode"] == "random" and meta["lighting"]["sky_texture"] == meta["appearance"]["sky"]
    assert json.loads((random_dir / "annotations.json").read_text()) == json.loads(
        (paper_dir / "annotations.json").read_text()
    )
    differ = 0
    for path in sorted((paper_dir / "images").iterdir()):
        ours = np.asarray(Image.open(random_dir / "images" / path.name)).astype(int)
        paper = np.asarray(Image.open(path)).astype(int)
        if path.suffix == ".png":
            assert np.array_equal(ours, paper), path.name  # masks, classes, depth
        else:
            differ += np.abs(ours - paper).mean() > 2
    assert differ == VIEWS


def test_a_scene_that_lost_its_labels_is_neither_skipped_nor_drawn_over(
    generated: tuple[Path, Path, dict], tmp_path: Path
) -> None:
    # A resumed run took a finished folder for a complete scene by its seed alone, so a scene whose
    # annotations.json was lost stayed lost; drawing over it could destroy what is left.
    from davis_ag.errors import UserError
    from davis_ag.generate.output_checks import check_scene_slot

    _, scene_dir, _ = generated
    root = tmp_path / "ds"
    shutil.copytree(scene_dir, root / REQUEST.folder)
    assert check_scene_slot(root, REQUEST) is True  # whole: skipped
    (root / REQUEST.folder / "annotations.json").unlink()
    before = snapshot(root)
    with pytest.raises(UserError, match=r"has lost its annotations.json .* move the folder out of the dataset"):
        check_scene_slot(root, REQUEST)
    assert snapshot(root) == before
