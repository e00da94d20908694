"""``davis-ag demo`` end to end at a tiny size (real Helios rendering), and its bad inputs."""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import pytest

from davis_ag import cli
from davis_ag.commands.arguments import image_size
from davis_ag.errors import UserError
from davis_ag.scene.specs import crop_spec, scenario_spec
from davis_ag.workflows.demo import run_demo


def _tiny_specs() -> tuple:
    """SP strawberry on a 1 x 1 m grid of 0.5 m steps (21 views instead of 285)."""
    scenario = replace(scenario_spec("sp"), extent=(1.0, 1.0), step=0.5)
    crop = replace(crop_spec("strawberry"), exclusion_radius=0.3)
    return scenario, crop


def test_demo_renders_validates_benchmarks_and_reports(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    from davis_ag.scene.plants import require_native_helios

    try:
        require_native_helios()
    except UserError as error:
        pytest.skip(str(error))
    scenario, crop = _tiny_specs()
    # A relative output folder from another working directory, as `make demo` passes it.
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "demo"
    code = run_demo(Path("demo"), scenes=1, size=(96, 54), episodes=5, sessions=2, scenario=scenario, crop=crop)
    printed = capsys.readouterr().out
    assert code == 0
    assert "sound" in printed
    assert "OER_tau" in printed and "Oracle" in printed
    index = out / "report" / "index.html"
    assert index.is_file() and "contact_sheet.png" in index.read_text()
    assert (out / "report" / "results.json").is_file()
    assert (out / "dataset" / "splits.json").is_file()
    # Re-running reuses the finished scene instead of rendering it again.
    assert run_demo(out, scenes=1, size=(96, 54), episodes=2, sessions=1, scenario=scenario,
                    crop=crop) == 0
    again = capsys.readouterr()
    assert "already complete" in again.out + again.err
    # ... but never one drawn at another size.
    with pytest.raises(UserError, match="96x54"):
        run_demo(out, scenes=1, size=(128, 72), episodes=2, sessions=1, scenario=scenario, crop=crop)


@pytest.mark.parametrize("text", ["abc", "10x10", "640", "0x360"])
def test_bad_sizes_are_refused(text: str) -> None:
    with pytest.raises(argparse.ArgumentTypeError, match="image size"):
        image_size(text)


def test_good_size_parses() -> None:
    assert image_size("640x360") == (640, 360)


@pytest.mark.parametrize("kwargs", [{"scenes": 0}, {"episodes": 0}, {"sessions": 0}, {"seed": -1}])
def test_bad_counts_are_user_errors(tmp_path: Path, kwargs: dict) -> None:
    with pytest.raises(UserError):
        run_demo(tmp_path / "out", **kwargs)


def test_cli_out_is_a_file_gives_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "file"
    target.write_text("x")
    assert cli.main(["demo", "--out", str(target)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("davis-ag demo: error:") and "\n" not in err


def test_cli_bad_size_exits_with_usage(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    with pytest.raises(SystemExit) as exited:
        cli.main(["demo", "--out", str(tmp_path), "--size", "big"])
    assert exited.value.code == 2
    assert "image size" in capsys.readouterr().err
