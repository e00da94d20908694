"""A long run's clock: a stage's wall time over every sitting, a killed one included."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from davis_ag.workflows.reproduce.clock import StageClock, generation_seconds, read_clock

KILLED_SITTING = """
import sys, time
from pathlib import Path
from davis_ag.workflows.reproduce.clock import StageClock
clock = StageClock(Path(sys.argv[1]), "0.1.0+killed", every_s=0.1)
with clock.timing("mp-vine: generate"):
    print("started", flush=True)
    time.sleep(60)
"""


def test_a_sitting_killed_without_warning_still_counts_up_to_its_last_write(tmp_path: Path) -> None:
    path = tmp_path / "clock.json"
    began = time.monotonic()  # before the child's clock starts: an upper bound on its sitting
    child = subprocess.Popen(
        [sys.executable, "-c", KILLED_SITTING, str(path)],
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": str(Path(__file__).parents[3] / "src")},
    )
    try:
        assert child.stdout is not None and child.stdout.readline() == "started\n"
        # Kill once a write of half a second is on disk (a fixed sleep fails when fsync stalls).
        deadline = time.monotonic() + 60
        while not (written := read_clock(path).get("mp-vine: generate")) or written[0]["seconds"] < 0.5:
            assert child.poll() is None and time.monotonic() < deadline, "the clock never wrote 0.5 s"
            time.sleep(0.05)
        child.send_signal(signal.SIGKILL)  # what the end of a session does: no finally, no exit handler
        alive_s = time.monotonic() - began
    finally:
        child.kill()
        child.wait()
    (sitting,) = read_clock(path)["mp-vine: generate"]
    assert 0.5 <= sitting["seconds"] <= alive_s + 0.05 and sitting["code"] == "0.1.0+killed"
    # The next sitting adds to it instead of starting the stage's time over.
    clock = StageClock(path, "0.1.0+next")
    with clock.timing("mp-vine: generate"):
        time.sleep(0.2)
    assert clock.sittings("mp-vine: generate") == 2
    first, second = clock.stages["mp-vine: generate"]
    assert first == sitting and second["seconds"] >= 0.2
    assert clock.seconds("mp-vine: generate") == round(first["seconds"] + second["seconds"], 1)


def test_a_sitting_with_nothing_to_do_is_left_out_and_other_stages_are_kept(tmp_path: Path) -> None:
    path = tmp_path / "clock.json"
    first = StageClock(path, "a")
    with first.timing("sp-strawberry: train A2C"):
        time.sleep(0.05)
    second = StageClock(path, "b")
    with second.timing("sp-strawberry: train A2C") as sitting:
        sitting.discard()  # the model was finished: reused, not trained
    with second.timing("sp-strawberry: evaluate"):
        pass
    stages = read_clock(path)
    assert [s["code"] for s in stages["sp-strawberry: train A2C"]] == ["a"]
    assert [s["code"] for s in stages["sp-strawberry: evaluate"]] == ["b"]
    with second.timing("mp-vine: generate") as sitting:
        sitting.discard()
    assert "mp-vine: generate" not in read_clock(path)
    # A clock with no stage left is a clock, not a damaged file.
    path.write_text('{"stages": {}}')
    assert StageClock(path, "c").stages == {} and not (tmp_path / "clock.json.unreadable").exists()
    assert second.seconds("mp-vine: generate") == 0 and second.started("mp-vine: generate") is None


def test_a_stage_that_fails_keeps_the_time_it_ran(tmp_path: Path) -> None:
    clock = StageClock(tmp_path / "clock.json", "a")
    with pytest.raises(RuntimeError), clock.timing("sp-strawberry: validate"):
        time.sleep(0.05)
        raise RuntimeError("stopped")
    assert read_clock(tmp_path / "clock.json")["sp-strawberry: validate"][0]["seconds"] >= 0.05


def test_an_unreadable_clock_is_kept_aside_not_overwritten(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "clock.json"
    path.write_text('{"stages": {"sp-strawberry: generate": [{"seconds": 5')  # cut short by hand
    clock = StageClock(path, "a")
    with clock.timing("sp-strawberry: generate"):
        pass
    assert (tmp_path / "clock.json.unreadable").read_text().endswith('"seconds": 5')
    assert "could not be read" in capsys.readouterr().out and clock.sittings("sp-strawberry: generate") == 1


def test_scenes_made_before_the_clock_count_their_own_times_over_the_scene_processes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A run begun before the clock existed: its finished scenes' scene.json times, spread over
    the scene processes that made them at once, join the clock's sittings."""
    from davis_ag.generate import run_progress

    monkeypatch.setattr(run_progress, "default_workers", lambda: 2)
    root = tmp_path / "dataset"
    for index, (grow, draw) in enumerate([(1.0, 99.0), (2.0, 198.0)]):
        scene = root / "Single-Strawberry" / f"{index:03d}"
        scene.mkdir(parents=True)
        metadata = {"views": [{}] * 285, "timing_s": {"grow": grow, "draw_and_label": draw}}
        (scene / "scene.json").write_text(json.dumps(metadata))
    old = time.time() - 3600
    for scene in ("000", "001"):
        os.utime(root / "Single-Strawberry" / scene / "scene.json", (old, old))
    clock = StageClock(tmp_path / "clock.json", "a")
    folders = ["Single-Strawberry/000", "Single-Strawberry/001"]
    seconds, note = generation_seconds(root, folders, clock, "sp-strawberry: generate")
    assert seconds == pytest.approx(150.0) and "2 scene(s) made before it" in note and "570 views" in note
    with clock.timing("sp-strawberry: generate"):
        time.sleep(0.1)
    seconds, note = generation_seconds(root, folders, clock, "sp-strawberry: generate")
    on_clock = clock.seconds("sp-strawberry: generate")
    assert seconds == pytest.approx(150.0 + on_clock) and on_clock >= 0.1 and "1 sitting(s) on the clock" in note


def test_each_sitting_says_where_it_ran_and_older_ones_are_counted_apart(tmp_path: Path) -> None:
    from davis_ag.workflows.reproduce.clock import machines

    path = tmp_path / "clock.json"
    path.write_text(json.dumps({"stages": {"train": [{"started": "2026-11-24T23:59:50+00:00", "seconds": 9.0}]}}))
    for machine in ("2 CPU cores, no GPU", "16 CPU cores, NVIDIA H200", "2 CPU cores, no GPU"):
        with StageClock(path, "a", machine=machine).timing("train"):
            pass
    sittings = read_clock(path)["train"]
    assert (
        machines(sittings)
        == "2 CPU cores, no GPU; 16 CPU cores, NVIDIA H200; 1 sitting(s) with no machine or CPU model recorded"
    )
    # Once the same machine is named with its CPU model, the bare name adds nothing: counted apart.
    with StageClock(path, "a", machine="2 CPU cores (Intel(R) Xeon(R) Processor), no GPU").timing("train"):
        pass
    assert machines(read_clock(path)["train"]) == (
        "16 CPU cores, NVIDIA H200; 2 CPU cores (Intel(R) Xeon(R) Processor), no GPU; "
        "3 sitting(s) with no machine or CPU model recorded"
    )
    assert machines([]) == "-"
