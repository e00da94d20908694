"""Every bad input the issue lists, typed as a user would: one line, exit status 2, no traceback,
nothing written, and refused before any long work (no plant grown, no model trained)."""

from __future__ import annotations

import errno
import json
import os
from pathlib import Path

import pytest

from davis_ag import cli
from layout_factory import write_tiny_dataset


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """``davis-ag ARGV`` in this process: exit status, stdout, stderr."""
    try:
        code = cli.main(list(argv))
    except SystemExit as exit_:  # argparse's refusals
        code = int(exit_.code or 0)
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def refused(capsys: pytest.CaptureFixture[str], *argv: str, status: int = 2) -> str:
    """Run expecting a refusal: ``status`` (2, bad input; 1, the machine) and exactly one line on
    stderr, which is returned."""
    code, out, err = run(capsys, *argv)
    assert code == status, (out, err)
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("davis-ag"), err
    return lines[0]


@pytest.fixture
def never_grow(monkeypatch: pytest.MonkeyPatch) -> None:
    """Fail the test if a plant starts growing or a model starts training: a refusal must come first."""

    def forbidden(*args: object, **kwargs: object) -> None:
        raise AssertionError("long work started before the arguments were checked")

    import davis_ag.benchmark.training as training
    import davis_ag.commands.generate as generate
    import davis_ag.commands.preview as preview
    import davis_ag.workflows.stages as stages

    monkeypatch.setattr(preview, "grow_scene", forbidden)
    monkeypatch.setattr(generate, "run_dataset", forbidden)
    monkeypatch.setattr(stages, "run_dataset", forbidden)
    monkeypatch.setattr(training, "make_vec_tvm", forbidden)


def test_unwritable_outputs_are_refused_before_any_work(
    capsys: pytest.CaptureFixture[str], sp_root: Path, tmp_path: Path, never_grow: None
) -> None:
    a_file = tmp_path / "a-file"
    a_file.write_text("x")
    for bad in ("/proc/x", str(a_file / "sub")):
        assert "cannot write in /proc" in refused(capsys, "generate", "--out", bad) or "file" in bad
        refused(capsys, "demo", "--out", bad)
        refused(capsys, "preview", "--out", bad)
        refused(capsys, "reproduce", "--out", bad, "--results", str(tmp_path / "r.md"))
        line = refused(capsys, "train", "--dataset", str(sp_root), "--scenario", "sp", "--out", f"{bad}/m.zip")
        assert "--out" in line
        line = refused(capsys, "evaluate", "--dataset", str(sp_root), "--scenario", "sp", "--out", f"{bad}/r.json")
        assert "--out" in line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-file"]


@pytest.mark.parametrize(
    "argv",
    [
        ["preview", "--seed", "-1"],
        ["preview", "--views", "0"],
        ["preview", "--views", "1,x"],
        ["preview", "--views", "100000"],
        ["preview", "--index", "-2"],
        ["preview", "--crop", "banana"],
        ["preview", "--size", "0x0"],
        ["preview", "--size", "99999x99999"],
        ["generate", "--size", "99999x99999"],
        ["generate", "--seed", "4294967296"],
        ["demo", "--size", "8193x16"],
        ["generate", "--seed", "-1"],
        ["generate", "--scenes", "0"],
        ["generate", "--first", "-1"],
        ["generate", "--crop", "banana"],
        ["generate", "--config", "nope.yaml"],
        ["demo", "--seed", "-1"],
        ["demo", "--scenes", "0"],
        ["demo", "--episodes", "0"],
        ["demo", "--sessions", "-3"],
        ["demo", "--scenes", "100000"],
        ["reproduce", "--sp-scenes", "0"],
        ["reproduce", "--mp-timesteps", "-5"],
    ],
)
def test_bad_values_of_commands_that_make_scenes(
    argv: list[str], capsys: pytest.CaptureFixture[str], tmp_path: Path, never_grow: None
) -> None:
    line = refused(capsys, *argv, "--out", str(tmp_path / "out"))
    assert argv[1] in line or "banana" in line or "nope" in line or "view" in line, line
    assert not (tmp_path / "out").exists()


def test_a_config_the_renderer_cannot_draw_is_refused_before_any_plant_grows(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, never_grow: None
) -> None:
    config = tmp_path / "huge.yaml"
    config.write_text("image_size: 99999x99999\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n")
    line = refused(capsys, "generate", "--config", str(config), "--out", str(tmp_path / "out"))
    assert line.endswith(
        f"{config}: image_size: 99999x99999: each side must be from 16 to 8192 pixels (the renderer's limit)"
    ), line
    config.write_text("groups: [{scenario: sp, crop: banana, scenes: 1}]\n")
    line = refused(capsys, "generate", "--config", str(config), "--out", str(tmp_path / "out"))
    assert "groups.0.crop: unknown crop 'banana': choose one of strawberry, tomato, vine, apple" in line, line
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--seed", "-1"], "--seed"),
        (["--policies", ","], "names nothing"),
        (["--policies", "LRD,Greedy"], "Greedy"),
        (["--episodes", "0"], "--episodes"),
        (["--sessions", "x"], "--sessions"),
        (["--policies", "A2C"], "unknown name 'A2C'"),
        (["--policy", "nowhere.py:act"], "no such file"),
        (["--name", "x"], "--name x: give it after the --policy it names"),
        (["--policy", "a.py:f", "--name", "x", "--name", "y"], "already named 'x'"),
        (["--model", "missing.zip"], "no such model"),
        (["--crop", "banana"], "banana"),
        (["--crop", "tomato"], "no sp/tomato scenes"),
        (["--scenario", "mp"], "no mp scenes"),
    ],
)
def test_bad_values_of_evaluate(
    extra: list[str], message: str, capsys: pytest.CaptureFixture[str], sp_root: Path, tmp_path: Path
) -> None:
    argv = ["evaluate", "--dataset", str(sp_root), "--scenario", "sp", "--out", str(tmp_path / "r.json"), *extra]
    assert message in refused(capsys, *argv)
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--seed", "-1"], "--seed"),
        (["--timesteps", "0"], "--timesteps"),
        (["--n-envs", "0"], "--n-envs"),
        (["--device", "banana"], "--device"),
        (["--verbose", "7"], "--verbose"),
        (["--crop", "vine"], "no sp/vine"),
        (["--algo", "sac"], "--algo"),
        (["--set", "n_steps"], "is not KEY=VALUE"),
        (["--algo", "ppo", "--set", "n_stepz=8"], "PPO setting 'n_stepz' cannot be changed"),
        (["--algo", "dqn", "--a2c-settings", "sb3"], "--a2c-settings is for --algo a2c"),
        (["--set", "use_rms_prop=false"], "A2C setting 'use_rms_prop' cannot be changed"),
    ],
)
def test_bad_values_of_train(
    extra: list[str], message: str, capsys: pytest.CaptureFixture[str], sp_root: Path, tmp_path: Path
) -> None:
    assert message in refused(
        capsys,
        "train",
        "--dataset",
        str(sp_root),
        "--scenario",
        "sp",
        "--out",
        str(tmp_path / "m.zip"),
        "--timesteps",
        "8",
        *extra,
    )
    assert not (tmp_path / "m.zip").exists()


def test_paths_that_are_not_datasets(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    empty, a_file = tmp_path / "empty", tmp_path / "file.txt"
    empty.mkdir()
    a_file.write_text("x")
    for where in (empty, a_file, tmp_path / "missing"):
        refused(capsys, "validate", str(where))
        refused(capsys, "evaluate", "--dataset", str(where), "--scenario", "sp", "--out", str(tmp_path / "r.json"))
        refused(capsys, "train", "--dataset", str(where), "--scenario", "sp", "--out", str(tmp_path / "m.zip"))
    refused(capsys, "validate", str(tmp_path), "--box-tolerance", "-1")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty", "file.txt"]


def test_an_empty_split_is_one_line(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    root = write_tiny_dataset(tmp_path / "one", "sp", "strawberry", scenes=1)  # no test scene
    assert "test split has none" in refused(
        capsys, "evaluate", "--dataset", str(root), "--scenario", "sp", "--out", str(tmp_path / "r.json")
    )


def test_a_model_trained_for_another_scenario(
    capsys: pytest.CaptureFixture[str], sp_root: Path, mp_root: Path, tmp_path: Path
) -> None:
    model = tmp_path / "sp.zip"
    code, _out, err = run(
        capsys,
        "train",
        "--dataset",
        str(sp_root),
        "--scenario",
        "sp",
        "--out",
        str(model),
        "--timesteps",
        "16",
        "--n-envs",
        "2",
        "--arch",
        "pooled",
        "--verbose",
        "0",
    )
    assert code == 0 and model.is_file(), err
    line = refused(
        capsys,
        "evaluate",
        "--dataset",
        str(mp_root),
        "--scenario",
        "mp",
        "--model",
        str(model),
        "--split",
        "all",
        "--out",
        str(tmp_path / "r.json"),
    )
    assert "7 actions" in line and "9" in line
    assert not (tmp_path / "r.json").exists()


def test_evaluate_keeps_its_results_when_the_final_write_fails(
    capsys: pytest.CaptureFixture[str], sp_root: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import davis_ag.benchmark.evaluation as evaluation

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    out = tmp_path / "r.json"
    write_json = evaluation.write_json

    def disk_full_at_out(results: dict, path: Path) -> Path:
        if Path(path) == out:  # the disk filled up during the evaluation
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        return write_json(results, path)

    monkeypatch.setattr(evaluation, "write_json", disk_full_at_out)
    line = refused(
        capsys,
        "evaluate",
        "--dataset",
        str(sp_root),
        "--scenario",
        "sp",
        "--episodes",
        "3",
        "--sessions",
        "1",
        "--out",
        str(out),
        status=1,
    )  # the machine's failure: exit 1
    assert "No space left on device" in line
    kept = Path(line.split("it was kept in ")[1].split(":")[0])
    assert json.loads(kept.read_text())["protocol"]["episodes"] == 3
    assert not out.exists()


def test_point_clouds_of_a_dataset_without_depth_or_camera(
    capsys: pytest.CaptureFixture[str], sp_root: Path, tmp_path: Path
) -> None:
    out = tmp_path / "clouds"
    line = refused(capsys, "export", "pointcloud", str(sp_root), str(out))
    assert "scene.json" in line or "depth" in line
    refused(capsys, "export", "pointcloud", str(sp_root), str(out), "--voxel", "-1")
    refused(capsys, "export", "pointcloud", str(sp_root), str(out), "--max-depth", "0")
    refused(capsys, "export", "pointcloud", str(tmp_path / "missing"), str(out))
    a_file = tmp_path / "file.txt"
    a_file.write_text("x")
    refused(capsys, "export", "pointcloud", str(sp_root), str(a_file))
    assert a_file.read_text() == "x"


def test_what_a_plant_library_crop_does_not_offer_is_refused_before_any_plant_grows(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, never_grow: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = str(tmp_path / "out")
    for command in ("generate", "preview"):
        line = refused(capsys, command, "--crop", "apple", "--plants", "canopy", "--out", out)
        assert "--plants canopy: apple grows from Helios's plant library only" in line, line
    line = refused(capsys, "generate", "--crop", "apple", "--scenario", "orchard", "--out", out)
    assert "unknown scenario 'orchard': choose sp (single plant), mp (multi plant) or row" in line, line
    # A row too large for the machine's memory: pretend it has 4 GB.
    import davis_ag.scene.scene_size as scene_size

    monkeypatch.setattr(scene_size, "machine_memory", lambda: 4 * 10**9)
    line = refused(capsys, "generate", "--crop", "vsp-vine", "--scenario", "row", "--out", out)
    assert "a row scene of vsp-vine holds 12 plants" in line and "4.0 GB" in line, line
    assert not (tmp_path / "out").exists()
