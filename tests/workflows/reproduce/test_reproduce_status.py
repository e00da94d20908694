"""``davis-ag reproduce --status``: where a run stands, stage by stage, from its files alone.

The run's folder is laid out here as ``reproduce`` and ``train`` leave it part way (the end of a
whole run is checked in ``test_reproduce.py``), so that every kind of stage shows."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from dataclasses import asdict, replace
from pathlib import Path

import pytest

from davis_ag import cli
from davis_ag.generate.run_progress import default_workers
from davis_ag.workflows.reproduce.configs import CONFIGS
from davis_ag.workflows.reproduce.status import run_status

CONFIG = replace(CONFIGS["small"], sp_scenes=3, sp_timesteps=30_000)


def a_run_part_way(out: Path) -> Path:
    """SP: 2 of 3 scenes made, A2C at 20,000 of 30,000 steps after a sitting of 400 s for 10,000."""
    folders = [f"Single-Strawberry/{i:03d}" for i in range(3)]
    for folder in folders[:2]:
        (out / "dataset" / folder).mkdir(parents=True)
        (out / "dataset" / folder / "annotations.json").write_text("{}")
    (out / "dataset" / "Single-Strawberry" / ".002.partial").mkdir()  # under way: not a scene
    timings = [
        {"grow": 10.0, "draw_and_label": 590.0},
        # Resumed after 95 of its 285 views: it drew 190 in 380 s, 2 s a view, as the first did.
        {"grow": 30.0, "draw_and_label": 380.0, "views_from_an_earlier_run": 95},
    ]
    for folder, timing in zip(folders, timings):
        (out / "dataset" / folder / "scene.json").write_text(json.dumps({"timing_s": timing}))
    state = {
        "config": asdict(CONFIG),
        "scene_folders": {"sp-strawberry": folders},
        "stages": {"sp-strawberry: generate": {"seconds": 7200.0, "note": "", "code": "x"}},
    }
    (out / "state.json").write_text(json.dumps(state))
    sittings = [{"started": "t", "seconds": 600.0, "code": "x"}, {"started": "t", "seconds": 300.0, "code": "x"}]
    clock = {"stages": {"sp-strawberry: train A2C": sittings}}
    (out / "clock.json").write_text(json.dumps(clock))
    (out / "models").mkdir()
    checkpoint = {
        "timesteps_done": 20_000,
        "sittings": [
            {"code": "x", "from_step": 0, "to_step": 10_000, "seconds": 900.0},
            {"code": "x", "from_step": 10_000, "to_step": 20_000, "seconds": 400.0},
        ],
        "selection": [{"step": 10_000, "oer_tau": 0.41}, {"step": 20_000, "oer_tau": 0.452}],
    }
    (out / "models" / "a2c_sp-strawberry.checkpoint.json").write_text(json.dumps(checkpoint))
    return out


def test_each_stage_says_what_its_files_show(tmp_path: Path) -> None:
    config, stages = run_status(a_run_part_way(tmp_path))
    assert config == CONFIG
    by_name = {s.stage: s for s in stages}
    assert list(by_name)[:5] == [
        "sp-strawberry: generate",
        "sp-strawberry: validate",
        "sp-strawberry: train A2C",
        "sp-strawberry: train PPO",
        "sp-strawberry: evaluate",
    ]
    made = by_name["sp-strawberry: generate"]
    assert (made.done, made.progress, made.seconds) == (False, "2 of 3 scenes", 7200.0)
    # One scene left, at the mean whole scene's time: the resumed one's drawing scaled to all its views.
    assert made.left_s == pytest.approx((600.0 + 30.0 + 570.0) / 2)
    a2c = by_name["sp-strawberry: train A2C"]
    assert not a2c.done and a2c.seconds == 900.0  # both sittings on the clock
    assert a2c.progress.startswith("20,000 of 30,000 steps at its last checkpoint (67 %)")
    assert a2c.progress.endswith("best train-split OER_tau 0.452 at 20,000 steps")
    assert a2c.left_s == pytest.approx(10_000 * 400.0 / 10_000)  # the last sitting's rate
    assert all(s.progress == "not started" and s.seconds is None for s in stages if s.stage.startswith("mp-"))


def test_the_status_prints_and_a_folder_without_a_run_gets_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = a_run_part_way(tmp_path / "run")
    assert cli.main(["reproduce", "--out", str(out), "--status"]) == 0
    printed = capsys.readouterr().out
    assert "| sp-strawberry: train A2C | no | 20,000 of 30,000 steps" in printed and "| 0.25 | 0.1 |" in printed
    assert not (tmp_path / "docs").exists()  # --status writes nothing, the results page included
    assert cli.main(["reproduce", "--out", str(tmp_path / "none"), "--status"]) == 2
    assert "no reproduce run started there" in capsys.readouterr().err


def test_a_reader_that_goes_away_stops_the_output_without_an_error(tmp_path: Path) -> None:
    """``davis-ag reproduce --status | head -1``: the exit a pipe's writer gets, nothing on stderr."""
    out = a_run_part_way(tmp_path / "run")
    read, write = os.pipe()
    os.close(read)
    done = subprocess.run(
        [sys.executable, "-m", "davis_ag.cli", "reproduce", "--out", str(out), "--status"],
        stdout=write,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
    )
    os.close(write)
    assert (done.returncode, done.stderr) == (141, "")


def test_a_learner_not_started_is_timed_at_its_rate_on_the_other_group(tmp_path: Path) -> None:
    """Once SP's A2C has trained, MP's is timed at its rate; what has no rate yet is named, not guessed."""
    from davis_ag.workflows.reproduce.status import format_status

    out = a_run_part_way(tmp_path)
    record = {"timesteps": 30_000, "seconds": 600.0, "steps_per_second": 50.0}
    (out / "models" / "a2c_sp-strawberry.training.json").write_text(json.dumps(record))
    by_name = {s.stage: s for s in run_status(out)[1]}
    mp_a2c = by_name["mp-vine: train A2C"]
    assert mp_a2c.progress == "not started; timed at sp-strawberry's 50.0 steps/s"
    assert mp_a2c.left_s == pytest.approx(CONFIG.mp_timesteps / 50.0)
    assert by_name["mp-vine: train PPO"].left_s is None  # SP's PPO has no record yet
    last = format_status(out).splitlines()[-3]  # the disk's line last
    timed = by_name["sp-strawberry: generate"].left_s + 400.0 + CONFIG.mp_timesteps / 50.0
    assert last.startswith(f"About {timed / 3600:.1f} hours left in the stages timed above, and ")
    assert last.endswith(
        "and 7 not timed yet (no rate measured for them): generate of mp-vine; validate of sp-strawberry, "
        "mp-vine; train PPO of sp-strawberry, mp-vine; evaluate of sp-strawberry, mp-vine."
    )


def test_a_learner_under_way_before_its_first_checkpoint_is_timed_at_the_other_groups_rate(tmp_path: Path) -> None:
    """MP's A2C has run 100 s on the clock and saved nothing yet: timed at SP's rate, less those 100 s."""
    out = a_run_part_way(tmp_path)
    record = {"timesteps": 30_000, "seconds": 600.0, "steps_per_second": 50.0}
    (out / "models" / "a2c_sp-strawberry.training.json").write_text(json.dumps(record))
    clock = json.loads((out / "clock.json").read_text())
    clock["stages"]["mp-vine: train A2C"] = [{"started": "t", "seconds": 100.0, "code": "x"}]
    (out / "clock.json").write_text(json.dumps(clock))
    mp_a2c = {s.stage: s for s in run_status(out)[1]}["mp-vine: train A2C"]
    assert mp_a2c.progress == "under way, no checkpoint yet; timed at sp-strawberry's 50.0 steps/s"
    assert mp_a2c.left_s == pytest.approx(CONFIG.mp_timesteps / 50.0 - 100.0)
    clock["stages"]["mp-vine: train A2C"][0]["seconds"] = CONFIG.mp_timesteps / 50.0 + 1  # slower than SP's
    (out / "clock.json").write_text(json.dumps(clock))
    mp_a2c = {s.stage: s for s in run_status(out)[1]}["mp-vine: train A2C"]
    whole = CONFIG.mp_timesteps / 50.0 / 3600
    assert (mp_a2c.progress, mp_a2c.left_s) == (
        f"under way, no checkpoint yet; past the {whole:.2f} h that sp-strawberry's 50.0 steps/s gives",
        None,
    )


def test_a_generate_stage_shows_its_views_before_its_first_scene_ends(tmp_path: Path) -> None:
    # A paper-scale MP vine scene takes about half an hour: the stage showed "not started" and no
    # time left for its first scenes. The journals of the scenes under way give both.
    from davis_ag.scene.view_grid import views_per_scene

    out = a_run_part_way(tmp_path)
    for index, views in ((0, 200), (1, 100)):
        partial = out / "dataset" / "Multi-Vine" / f".{index:03d}.partial"
        partial.mkdir(parents=True)
        (partial / "views.jsonl").write_text('{"name": "x"}\n' * views)
    clock = json.loads((out / "clock.json").read_text())
    clock["stages"]["mp-vine: generate"] = [{"started": "t", "seconds": 600.0, "code": "x"}]
    (out / "clock.json").write_text(json.dumps(clock))
    stage = {s.stage: s for s in run_status(out)[1]}["mp-vine: generate"]
    assert (stage.done, stage.progress, stage.seconds) == (
        False,
        "0 of 2 scenes; 2 more under way (300 views drawn)",
        600.0,
    )
    views = views_per_scene(*CONFIG.specs("mp", "vine"))
    assert stage.left_s == pytest.approx((2 * views - 300) * 600.0 / 300)


def test_a_validation_not_started_is_timed_at_the_other_groups_last_check(tmp_path: Path) -> None:
    # SP strawberry was checked whole twice (its validator changed); MP vine reads at the views per
    # second of the last check, not of the two added up.
    from davis_ag.scene.view_grid import views_per_scene

    out = a_run_part_way(tmp_path)
    state = json.loads((out / "state.json").read_text())
    state["stages"]["sp-strawberry: validate"] = {
        "seconds": 900.0,
        "note": "checked 3 scenes: sound",
        "code": "x",
        "check_seconds": 300.0,
    }
    (out / "state.json").write_text(json.dumps(state))
    clock = json.loads((out / "clock.json").read_text())
    clock["stages"]["sp-strawberry: validate"] = [
        {"started": "t", "seconds": 600.0, "code": "x"},
        {"started": "t", "seconds": 300.0, "code": "y"},
        {"started": "t", "seconds": 20.0, "code": "z"},  # a re-check stopped early: not a whole check
    ]
    (out / "clock.json").write_text(json.dumps(clock))
    sp_views = CONFIG.sp_scenes * views_per_scene(*CONFIG.specs("sp", "strawberry"))
    mp_views = CONFIG.mp_scenes * views_per_scene(*CONFIG.specs("mp", "vine"))
    stage = {s.stage: s for s in run_status(out)[1]}["mp-vine: validate"]
    assert not stage.done and stage.progress.startswith(f"not started; {mp_views:,} views, timed at sp-strawberry's")
    assert stage.left_s == pytest.approx(mp_views * 300.0 / sp_views)
    # Once MP's own check is on the clock (running, or stopped part way), it is no longer "not started".
    clock["stages"]["mp-vine: validate"] = [{"started": "t", "seconds": 60.0, "code": "x"}]
    (out / "clock.json").write_text(json.dumps(clock))
    stage = {s.stage: s for s in run_status(out)[1]}["mp-vine: validate"]
    assert (stage.done, stage.progress, stage.seconds) == (False, "started, not finished", 60.0)


def test_an_evaluation_not_started_is_timed_at_another_groups_same_scenario_first(tmp_path: Path) -> None:
    # The same policies and 3 x 200 episodes on every group: the crops run's 20 evaluations were
    # "not timed yet" though each takes what the first took, give or take its scenes.
    out = a_run_part_way(tmp_path)
    pairs = (("sp", "strawberry"), ("mp", "vine"), ("sp", "tomato"))
    state = json.loads((out / "state.json").read_text())
    state["config"]["pairs"] = [list(pair) for pair in pairs]
    (out / "state.json").write_text(json.dumps(state))
    assert {s.stage: s for s in run_status(out)[1]}["sp-tomato: evaluate"].left_s is None  # nothing to go by
    clock = json.loads((out / "clock.json").read_text())
    for key, seconds in (("mp-vine", 90.0), ("sp-strawberry", 30.0)):
        clock["stages"][f"{key}: evaluate"] = [{"started": "t", "seconds": seconds, "code": "x"}]
        (out / "results").mkdir(exist_ok=True)
        (out / "results" / f"{key}.json").write_text("{}")
    (out / "clock.json").write_text(json.dumps(clock))
    stage = {s.stage: s for s in run_status(out)[1]}["sp-tomato: evaluate"]
    assert (stage.done, stage.progress, stage.left_s) == (False, "not started; timed at sp-strawberry's 30 s", 30.0)


def test_scenes_left_go_in_rounds_of_the_scene_processes_and_a_scene_wholly_resumed_gives_no_rate(
    tmp_path: Path,
) -> None:
    """Five scenes left on a machine running two scene processes at once take three rounds of a scene's time."""
    from davis_ag.workflows.reproduce.status import _generation_left

    for folder, timing in (
        ("a", {"grow": 10.0, "draw_and_label": 90.0}),
        ("b", {"grow": 5.0, "draw_and_label": 0.1, "views_from_an_earlier_run": 20}),  # nothing drawn here
    ):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "scene.json").write_text(json.dumps({"timing_s": timing}))
    rounds = -(-5 // default_workers())
    assert _generation_left(tmp_path, ["a", "b"], 5, views=20) == pytest.approx(rounds * 100.0)
    assert _generation_left(tmp_path, ["b"], 5, views=20) is None
    assert _generation_left(tmp_path, ["a"], 0, views=20) is None


def test_a_cell_s_learner_not_started_is_timed_at_the_median_rate_of_the_cells_trained(tmp_path: Path) -> None:
    """A cells run (robot, structures): a learner is timed once some cell has trained the same one."""
    from davis_ag.workflows.reproduce.cells import Cell
    from davis_ag.workflows.reproduce.status import StageStatus, _timed_from_other_cells

    cells = [Cell(f"row-vsp-vine-{k}", tmp_path / "dataset", "row", "vsp-vine") for k in ("a", "b", "c", "d")]
    (tmp_path / "models").mkdir()
    for cell, rate in zip(cells[:3], (20.0, 40.0, 100.0)):
        record = {"timesteps": 10_000, "steps_per_second": rate}
        (tmp_path / "models" / f"a2c_{cell.key}.training.json").write_text(json.dumps(record))
    waiting = StageStatus("row-vsp-vine-d: train A2C", False, "not started")
    timed = _timed_from_other_cells(tmp_path, cells, "a2c", 10_000, waiting)
    assert timed.left_s == pytest.approx(10_000 / 40.0)
    assert timed.progress == "not started; timed at the median 40.0 steps/s of 3 cell(s) trained"
    running = replace(waiting, progress="under way, no checkpoint yet", seconds=100.0)
    assert _timed_from_other_cells(tmp_path, cells, "a2c", 10_000, running).left_s == pytest.approx(150.0)
    assert _timed_from_other_cells(tmp_path, cells, "ppo", 10_000, waiting) == waiting  # no PPO trained yet


@pytest.mark.parametrize(
    ("free", "ending"),
    [
        ("both", "GB free there."),
        ("the larger", "GB free there: not all at once; run a group at a time (`--only`), or free space."),
        ("the smaller", "GB free there: {larger} cannot fit; free space, or move the run to a larger disk."),
    ],
)
def test_the_status_says_what_each_group_still_writes_to_disk_and_what_does_not_fit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, free: str, ending: str
) -> None:
    """A paper-scale run's MP vine writes about 52 GB: the status says so before the next sitting is
    refused for it, and whether ``--only`` one group at a time would fit."""
    from davis_ag.workflows.reproduce import configs
    from davis_ag.workflows.reproduce.status import format_status

    out = a_run_part_way(tmp_path / "run")
    sp, mp = (configs.disk_needed(CONFIG, out / "dataset", [pair]) * configs.DISK_MARGIN for pair in CONFIG.pairs)
    # The made scenes are not counted again: SP with 2 of its 3 scenes made writes less than with none.
    assert 0 < sp < configs.disk_needed(CONFIG, tmp_path / "empty", [CONFIG.pairs[0]]) * configs.DISK_MARGIN
    (_, small), (larger, large) = sorted([("sp-strawberry", sp), ("mp-vine", mp)], key=lambda kv: kv[1])
    room = {"both": sp + mp, "the larger": large, "the smaller": small}[free]
    monkeypatch.setattr(configs, "free_bytes", lambda out: room)
    line = format_status(out).splitlines()[-1]
    assert line.startswith("Disk, still to write under the dataset")
    assert f"sp-strawberry {sp / 1e9:.1f} GB, mp-vine {mp / 1e9:.1f} GB; {room / 1e9:.1f} GB free there" in line
    assert line.endswith(ending.format(larger=larger))
