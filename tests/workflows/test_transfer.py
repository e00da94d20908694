"""``davis-ag transfer`` end to end on CPU: tiny DAVIS-Ag pre-training, a shifted synthetic stand-in
for the real set, two splits, both arms, scores like Table 5, and no network access attempted."""

from __future__ import annotations

import json
import socket
from pathlib import Path

import pytest

from davis_ag.cli import main
from davis_ag.workflows.transfer import PAPER_TABLE5
from layout_factory import write_tiny_dataset


def test_transfer_runs_end_to_end_offline(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    pretrain = write_tiny_dataset(tmp_path / "pretrain", "sp", "strawberry", scenes=2, size=(64, 48))
    held_out = write_tiny_dataset(tmp_path / "held-out", "sp", "strawberry", scenes=2, seed=5, size=(64, 48))
    assert main(["export", "yolo", str(held_out), str(tmp_path / "standin"), "--appearance-shift", "0"]) == 0

    attempts: list[tuple] = []

    def refuse(*args: object, **kwargs: object) -> None:
        attempts.append(args)
        raise OSError("no network in this test")

    monkeypatch.setattr(socket, "getaddrinfo", refuse)
    monkeypatch.setattr(socket.socket, "connect", refuse)
    out = tmp_path / "out"
    argv = [
        "transfer",
        "--pretrain",
        str(pretrain),
        "--real",
        str(tmp_path / "standin" / "data.yaml"),
        "--real-label",
        "stand-in: shifted synthetic scenes",
        "--out",
        str(out),
        "--splits",
        "2",
        "--train-size",
        "24",
        "--test-size",
        "8",
        "--epochs",
        "1",
        "--pretrain-epochs",
        "1",
        "--imgsz",
        "64",
        "--batch",
        "8",
        "--results",
        str(tmp_path / "results.md"),
    ]
    assert main(argv) == 0
    assert attempts == []

    printed = capsys.readouterr().out
    assert "| mAP@50 |" in printed and "DAVIS-Ag -> Real 2" in printed
    results = json.loads((out / "transfer.json").read_text())
    assert results["split_sizes"] == {"train": 24, "test": 8} and len(results["splits"]) == 2
    for split in results["splits"]:
        for arm in ("real_only", "transfer"):
            assert 0.0 <= split[arm]["map50_95"] <= split[arm]["map50"] <= 1.0
    # The two arms are different models: the fine-tuned one started from the pre-trained weights.
    assert (out / "runs" / "pretrain" / "weights" / "last.pt").is_file()
    fine_tuned = json.loads((out / "split1" / "runs" / "transfer" / "done.json").read_text())
    assert fine_tuned["start"].endswith("last.pt") and fine_tuned["start_weights_carried"] > 0.9
    assert json.loads((out / "split1" / "runs" / "real_only" / "done.json").read_text())["start"] is None
    report = (tmp_path / "results.md").read_text()
    assert "stand-in" in report and "0.943" in report  # the paper's Table 5 sits beside ours, named
    assert results["paper_table5"] == PAPER_TABLE5
    # A second run reuses every finished split (and replaces the report only with --force).
    assert main(argv) == 2 and "--results" in capsys.readouterr().err
    assert main([*argv, "--force"]) == 0
    again = json.loads((out / "transfer.json").read_text())
    assert again["splits"] == results["splits"]
    # ... and keeps the times its first sitting measured (it wrote 0 s for every reused stage).
    for stage in ("pre-train", "split 1", "split 2"):
        assert again["wall_s"][stage] == results["wall_s"][stage] > 0
    assert list(again["wall_s"]) == list(results["wall_s"])  # in the order the stages ran
    # A folder from before the settings were recorded takes them from its transfer.json.
    (out / "transfer-config.json").unlink()
    assert main([*argv, "--force"]) == 0 and (out / "transfer-config.json").is_file()
    # A run of other settings would report the folder's scores as its own: refused.
    assert main([*argv[:-2], "--seed", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert "holds a transfer run of other settings (seed: 0 against 1)" in err and "\n" not in err


def test_transfer_with_a_missing_real_set_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    pretrain = write_tiny_dataset(tmp_path / "pretrain", "sp", "strawberry", scenes=2, size=(64, 48))
    assert (
        main(
            [
                "transfer",
                "--pretrain",
                str(pretrain),
                "--real",
                str(tmp_path / "nothing"),
                "--out",
                str(tmp_path / "out"),
            ]
        )
        == 2
    )
    err = capsys.readouterr().err
    assert "not a labelled set" in err and len(err.strip().splitlines()) == 1
