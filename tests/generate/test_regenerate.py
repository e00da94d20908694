"""``davis-ag verify``: a scene made again from its records comes out byte for byte, and any change
to its files, or records that cannot rebuild it, is named."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from davis_ag.cli import main
from davis_ag.errors import UserError
from davis_ag.generate.regenerate import request_for, verify_scene
from davis_ag.generate.run_config import load_dataset_config
from davis_ag.generate.run_progress import RunOptions
from davis_ag.generate.runner import run_dataset

#: A strawberry scene of 7 views on a grid of its own and the README altitudes, and a vine scene of
#: 2 x 2 positions with 2 headings: the grid, the altitudes and the scenario come from the records.
TINY = """\
seed: 5
image_size: 64x48
strawberry_altitudes: readme
groups:
  - {scenario: sp, crop: strawberry, scenes: 1, first: 2, grid: {extent: [3.0, 3.0], step: 1.5, altitude_levels: [0]}}
  - {scenario: mp, crop: vine, scenes: 1, grid: {extent: [1.0, 1.0], step: 1.0, altitude_levels: [0], headings: 2}}
"""


@pytest.fixture(scope="module")
def tiny_config(tmp_path_factory: pytest.TempPathFactory) -> Path:
    config = tmp_path_factory.mktemp("config") / "tiny.yaml"
    config.write_text(TINY)
    return config


@pytest.fixture(scope="module")
def dataset(tiny_config: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("data") / "data"
    run_dataset(load_dataset_config(tiny_config).requests(), root, RunOptions(workers=1, progress=False))
    return root


@pytest.fixture
def copy(dataset: Path, tmp_path: Path) -> Path:
    return Path(shutil.copytree(dataset, tmp_path / "data"))


def test_a_scene_is_rebuilt_from_its_records(dataset: Path, tiny_config: Path) -> None:
    # The grid, the README altitudes and the vine's two headings come back from scene.json alone.
    made = {r.folder: r for r in load_dataset_config(tiny_config).requests()}
    for scene in ("Single-Strawberry/002", "Multi-Vine/000"):
        assert request_for(dataset / scene) == made[scene]
    assert made["Single-Strawberry/002"].crop.altitudes == (0.50, 0.75, 1.00)
    assert made["Multi-Vine/000"].scenario.headings == 2


def test_a_scene_without_depth_and_with_a_random_look_is_rebuilt_too(tmp_path: Path) -> None:
    config = tmp_path / "other.yaml"
    config.write_text(
        "seed: 9\nimage_size: 48x32\ndepth: false\nappearance: random\n"
        "groups:\n  - {scenario: sp, crop: strawberry, scenes: 1, grid: {extent: [3.0, 3.0], step: 1.5, altitude_levels: [1]}}\n"
    )
    (made,) = load_dataset_config(config).requests()
    run_dataset([made], tmp_path / "data", RunOptions(workers=1, progress=False))
    assert request_for(tmp_path / "data" / made.folder) == made


def test_both_scenes_come_out_identical_and_the_dataset_is_untouched(
    dataset: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    before = {p: p.stat().st_mtime_ns for p in dataset.rglob("*")}
    monkeypatch.chdir(dataset.parent)  # relative paths, as a user types them
    assert main(["verify", "data/Single-Strawberry/002", "data/Multi-Vine/000", "--keep", str(tmp_path / "again")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("Single-Strawberry/002: identical, ") and "files byte for byte" in lines[0]
    assert lines[1].startswith("Multi-Vine/000: identical, ")
    assert lines[-1] == "2 of 2 scenes identical"
    assert {p: p.stat().st_mtime_ns for p in dataset.rglob("*")} == before
    assert (tmp_path / "again" / "Multi-Vine" / "000" / "annotations.json").is_file()  # kept as asked


def test_a_changed_file_is_named(copy: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scene = copy / "Single-Strawberry" / "002"
    mask = next((scene / "images").glob("*_seg.png"))
    data = bytearray(mask.read_bytes())
    data[-20] ^= 1
    mask.write_bytes(bytes(data))
    assert main(["verify", str(scene)]) == 1
    (line,) = capsys.readouterr().out.splitlines()
    assert line.startswith("Single-Strawberry/002: 1 of ") and f"files differ (images/{mask.name}; made by " in line


def test_a_live_cache_beside_the_scene_is_not_a_difference(copy: Path) -> None:
    from davis_ag.formats.layout import LIVE_GEOMETRY

    scene = copy / "Multi-Vine" / "000"
    (scene / LIVE_GEOMETRY).write_bytes(b"written by davis-ag live, not by generate")
    assert verify_scene(scene, progress=False).identical


def test_what_cannot_be_verified_is_refused_in_one_line_before_any_scene_is_made(
    copy: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    def refused(*argv: str) -> str:
        assert main(["verify", *argv]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1, err
        return err

    moved = copy / "Single-Strawberry" / "007"
    (copy / "Single-Strawberry" / "002").rename(moved)  # a scene folder renamed by hand
    assert "records scene Single-Strawberry/002, not this folder: was the folder renamed" in refused(str(moved))
    # A group or a dataset is not a scene: the line names one of its scenes to give instead.
    assert f"is not a scene folder: give scene folders, such as {copy / 'Multi-Vine' / '000'}" in refused(str(copy))
    assert "is not a scene folder: give scene folders, such as " in refused(str(copy / "Single-Strawberry"))
    vine = copy / "Multi-Vine" / "000"
    assert "is given twice" in refused(str(vine), str(copy / "Multi-Vine" / ".." / "Multi-Vine" / "000"))
    # --keep inside the dataset would write there, through `..` too; a full folder could mix scenes.
    for keep in (copy / "again", tmp_path / "elsewhere" / ".." / "data" / "again"):
        assert "which is a dataset: only davis-ag generate writes there" in refused(str(vine), "--keep", str(keep))
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "notes.txt").write_text("mine")
    assert "is not empty" in refused(str(vine), "--keep", str(tmp_path / "full"))
    assert not (copy / "again").exists() and (tmp_path / "full" / "notes.txt").read_text() == "mine"
    # Two datasets' scenes of one id would meet in one --keep folder: refused; apart, both are fine.
    other = Path(shutil.copytree(copy, tmp_path / "other"))
    assert "two scenes given are Multi-Vine/000" in refused(
        str(vine), str(other / "Multi-Vine" / "000"), "--keep", str(tmp_path / "one")
    )
    # A folder that already holds the scene would be compared, not made again.
    (tmp_path / "holds" / "Multi-Vine" / "000").mkdir(parents=True)
    with pytest.raises(UserError, match="already exists: make the scene again in another folder"):
        verify_scene(vine, tmp_path / "holds", progress=False)


def test_scene_json_records_the_opengl_implementation_that_drew_it(dataset: Path) -> None:
    from davis_ag.formats.scene_file import read_scene_file
    from davis_ag.render.egl_context import renderer_name

    generator = read_scene_file(dataset / "Single-Strawberry" / "002" / "scene.json").generator
    assert generator is not None and generator.gl_renderer == renderer_name()


def test_a_scene_drawn_by_another_opengl_implementation_says_so(copy: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A scene made on a GPU and verified on llvmpipe (or the other way): its pixels differ, and
    the line says which implementations drew it and whether the labels came out the same."""
    import json

    from davis_ag.render.egl_context import draws_on_gpu, renderer_name

    # The other side of this machine: a GPU's name where llvmpipe draws here, llvmpipe's on a GPU.
    other = "llvmpipe (LLVM 15.0.6, 256 bits)" if draws_on_gpu(renderer_name()) else "NVIDIA H200/PCIe/SSE2"
    scene = copy / "Single-Strawberry" / "002"
    record = json.loads((scene / "scene.json").read_text())
    record["generator"]["gl_renderer"] = other  # as the other machine records it
    (scene / "scene.json").write_text(json.dumps(record))
    view = next((scene / "images").glob("*.jpeg"))  # its pixels, drawn by the other implementation
    view.write_bytes(view.read_bytes()[:-2] + b"\x00\xff\xd9")
    assert main(["verify", str(scene)]) == 1
    (line,) = capsys.readouterr().out.splitlines()
    assert "1 of " in line and f"images/{view.name}" in line
    assert f"drawn by {other}, drawn again by {renderer_name()}: " in line
    assert "annotations.json came out the same" in line

    del record["generator"]["gl_renderer"]  # a scene made before the record: said so
    (scene / "scene.json").write_text(json.dumps(record))
    assert main(["verify", str(scene)]) == 1
    assert "where the scene does not record what drew it" in capsys.readouterr().out


def test_a_differing_scene_of_the_same_implementation_names_no_implementation() -> None:
    from davis_ag.generate.regenerate import Verdict

    verdict = Verdict("Single-Strawberry/000", 4, ("images/0001.jpeg",), "a", "b", "llvmpipe", "llvmpipe")
    assert "OpenGL" not in verdict.text() and "1 of 4 files differ" in verdict.text()
