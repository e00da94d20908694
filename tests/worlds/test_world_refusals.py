"""Bad input to the 3-D exports: one line, exit status 2, nothing written."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from davis_ag import cli
from layout_factory import write_original_style_dataset


def refused(capsys: pytest.CaptureFixture[str], *argv: str) -> str:
    """Run ``davis-ag ARGV`` expecting a refusal: status 2 and one line on stderr, returned."""
    code = cli.main(list(argv))
    out, err = capsys.readouterr()
    assert code == 2 and "Traceback" not in out + err, (out, err)
    (line,) = err.splitlines()
    return line


@pytest.mark.parametrize("fmt", ["usd", "mesh", "nerfstudio"])
def test_the_original_download_has_no_geometry(capsys: pytest.CaptureFixture[str], tmp_path: Path, fmt: str) -> None:
    original = write_original_style_dataset(tmp_path / "davis")
    out = tmp_path / "out"
    line = refused(capsys, "export", fmt, str(original), str(out))
    assert "scene.json" in line and "davis-ag generate" in line
    assert not out.exists()


def test_an_export_that_exists_is_kept_without_force(
    capsys: pytest.CaptureFixture[str], world_root: Path, tmp_path: Path
) -> None:
    out = tmp_path / "ns"
    assert cli.main(["export", "nerfstudio", str(world_root), str(out)]) == 0
    written = sorted(out.rglob("transforms.json"))
    before = [p.read_bytes() for p in written]
    assert "--force" in refused(capsys, "export", "nerfstudio", str(world_root), str(out))
    assert [p.read_bytes() for p in written] == before
    assert cli.main(["export", "nerfstudio", str(world_root), str(out), "--force", "--copy"]) == 0
    assert [p.read_bytes() for p in written] != before  # replaced: now with copied images
    foreign = tmp_path / "mine"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("keep")
    assert "not a usd export" in refused(capsys, "export", "usd", str(world_root), str(foreign), "--force")
    assert (foreign / "notes.txt").read_text() == "keep"


def test_usd_without_usd_core_is_refused_before_anything_is_written(
    capsys: pytest.CaptureFixture[str], world_root: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "pxr", None)  # as where the worlds extra is not installed
    out = tmp_path / "usd"
    assert "usd-core" in refused(capsys, "export", "usd", str(world_root), str(out))
    assert not out.exists()
