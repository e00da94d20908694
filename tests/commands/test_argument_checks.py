"""The shared argument types and output checks: values refused as parsed, output paths proven
writable by creating a file (``os.access`` says yes to root everywhere), results rescued."""

from __future__ import annotations

import argparse
import errno
import os
from pathlib import Path

import pytest

from davis_ag.atomic_files import prove_writable_file, prove_writable_folder, write_or_rescue
from davis_ag.commands import arguments
from davis_ag.errors import UserError


@pytest.mark.parametrize("text", ["-1", "x", "", "1.5", "4294967296", "²", " "])
def test_bad_seeds_are_refused(text: str) -> None:
    with pytest.raises(argparse.ArgumentTypeError, match=r"seed|whole"):
        arguments.seed(text)


@pytest.mark.parametrize("text, value", [("0", 0), ("7", 7), ("4294967295", 2**32 - 1)])
def test_good_seeds(text: str, value: int) -> None:
    assert arguments.seed(text) == value


def test_counts_and_bounds() -> None:
    assert arguments.count("3") == 3 and arguments.whole("0") == 0 and arguments.bounded(1, 5)("5") == 5
    for parse, text in [
        (arguments.count, "0"),
        (arguments.count, "-2"),
        (arguments.whole, "-1"),
        (arguments.bounded(1, 5), "6"),
        (arguments.bounded(1, 5), "0"),
    ]:
        with pytest.raises(argparse.ArgumentTypeError):
            parse(text)


def test_name_lists() -> None:
    parse = arguments.name_list(("LRD", "UDD", "Oracle"))
    assert parse("lrd, Oracle,lrd") == ["LRD", "Oracle"]
    for text, message in [(",", "names nothing"), ("", "names nothing"), ("LRD,Greedy", "unknown name 'Greedy'")]:
        with pytest.raises(argparse.ArgumentTypeError, match=message):
            parse(text)


def test_number_lists() -> None:
    assert arguments.number_list("1, 40,1") == [1, 40]
    for text in ["0", "1,,2", "a", "", "-3"]:
        with pytest.raises(argparse.ArgumentTypeError):
            arguments.number_list(text)


def test_paths_are_absolute_and_never_empty(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert arguments.path("out") == tmp_path / "out"
    for text in ["", "  ", "a\0b"]:
        with pytest.raises(argparse.ArgumentTypeError):
            arguments.path(text)


def _unwritable(tmp_path: Path) -> list[tuple[Path, str]]:
    """Places no run can write, as root too: /proc, a path under a regular file."""
    a_file = tmp_path / "a-file"
    a_file.write_text("x")
    return [
        (Path("/proc/x"), "cannot write in /proc"),
        (Path("/proc/x/y/z"), "cannot write in /proc"),
        (a_file / "sub", "which is a file"),
        (a_file / "sub" / "deeper", "which is a file"),
    ]


def test_folders_are_proven_writable_by_creating_a_file(tmp_path: Path) -> None:
    before = sorted(tmp_path.rglob("*"))
    assert prove_writable_folder(tmp_path / "new" / "deep") == tmp_path / "new" / "deep"
    assert sorted(tmp_path.rglob("*")) == before  # nothing created, nothing left behind
    for path, message in _unwritable(tmp_path):
        with pytest.raises(UserError, match=message):
            prove_writable_folder(path)
    (tmp_path / "file").write_text("x")
    with pytest.raises(UserError, match="is a file"):
        prove_writable_folder(tmp_path / "file")


def test_files_are_proven_writable_by_creating_a_file(tmp_path: Path) -> None:
    before = sorted(tmp_path.rglob("*"))
    assert prove_writable_file(tmp_path / "models" / "m.zip") == tmp_path / "models" / "m.zip"
    assert sorted(tmp_path.rglob("*")) == before
    for path, message in _unwritable(tmp_path):
        with pytest.raises(UserError, match=message):
            prove_writable_file(path / "m.zip")
    with pytest.raises(UserError, match="is a folder"):
        prove_writable_file(tmp_path)


def test_a_result_whose_write_fails_is_kept_elsewhere(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    target = tmp_path / "results.json"

    def write(path: Path) -> None:
        if path == target:  # the disk filled up while the result was being made
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        path.write_text("the result")

    with pytest.raises(UserError) as error:
        write_or_rescue(target, write, "the results")
    message = str(error.value)
    assert "No space left on device" in message and "\n" not in message
    kept = Path(message.split("it was kept in ")[1].split(":")[0])
    assert kept.read_text() == "the result" and kept.is_relative_to(tmp_path / "cache")
    assert not target.exists()
    assert write_or_rescue(tmp_path / "fine.json", lambda p: p.write_text("ok"), "x") == tmp_path / "fine.json"
