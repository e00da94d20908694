"""Progress in a log: no bar redrawn per view when stderr is not a terminal, but a line per
finished scene and a line every so often with the views done and the time left."""

from __future__ import annotations

import pytest

import davis_ag.generate.run_progress as run_progress
from davis_ag.generate.one_scene import SceneRequest
from davis_ag.scene.specs import CROPS, SCENARIOS


def test_no_bars_in_a_log_but_a_line_per_scene_and_per_interval(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    requests = [SceneRequest(SCENARIOS["sp"], CROPS["strawberry"], i, 0) for i in range(2)]
    views = run_progress.count_views(SCENARIOS["sp"], CROPS["strawberry"])
    monkeypatch.setattr(run_progress, "LOG_INTERVAL_S", 0.0)  # a line at every event, to see one
    progress = run_progress.Progress(requests, enabled=True)  # stderr is captured: not a terminal
    for request in requests:
        progress.event(("start", request.folder))
        for done in range(1, views + 1):
            progress.event(("view", request.folder, done, views))
        progress.finished(request, {"views": views, "grow_s": 1.0, "views_s": 2.0})
    progress.close()
    err = capsys.readouterr().err
    assert "\r" not in err and "\x1b[" not in err  # no bar, no cursor movement
    lines = err.splitlines()
    assert [line for line in lines if line.startswith("Single-Strawberry/")] == [
        f"Single-Strawberry/00{i}: {views} views, grown in 1.0 s, {2 / views:.3f} s per view" for i in range(2)
    ]
    assert f"{2 * views} of {2 * views} views (100 %), 0 min left" in lines


def test_the_interval_keeps_logs_short(capsys: pytest.CaptureFixture[str]) -> None:
    request = SceneRequest(SCENARIOS["sp"], CROPS["strawberry"], 0, 0)
    progress = run_progress.Progress([request], enabled=True)
    progress.event(("start", request.folder))
    for done in range(1, 353):
        progress.event(("view", request.folder, done, 352))
    progress.close()
    assert capsys.readouterr().err == ""  # well within a minute: nothing yet


def test_large_scenes_get_as_many_processes_as_memory_holds(monkeypatch: pytest.MonkeyPatch) -> None:
    import os

    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.generate.run_progress import default_workers
    from davis_ag.scene.specs import CROPS, scenario_spec

    monkeypatch.setattr(os, "cpu_count", lambda: 16)
    monkeypatch.setattr(os, "sysconf", lambda name: {"SC_PHYS_PAGES": 24 * 2**18, "SC_PAGE_SIZE": 4096}[name])
    small = [SceneRequest(scenario_spec("sp", CROPS["strawberry"]), CROPS["strawberry"], 0, 0)]
    row = CROPS["cherry-tomato"]
    large = [SceneRequest(scenario_spec("row", row), row, 0, 0), *small]
    assert default_workers(small) == 8  # 24 GiB of 3 GiB processes
    assert default_workers(large) == 1  # one 18 GB row at a time
