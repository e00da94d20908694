"""`davis-ag verify RESULTS.json --dataset DATA` on TVMContinuous-v0: the seeded starts and the
recorded actions played again, every pose drawn again (issue 44)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from davis_ag import cli
from davis_ag.benchmark.results import EvaluationResults
from davis_ag.benchmark.summaries import session_metrics


def test_a_continuous_evaluation_replays_sound_and_a_moved_pose_is_named(
    live_root: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    evaluate = ["evaluate", "--env", "continuous", "--dataset", str(live_root), "--scenario", "sp"]
    assert (
        cli.main(
            [
                *evaluate,
                "--split",
                "all",
                "--episodes",
                "2",
                "--sessions",
                "1",
                "--policies",
                "LR,Rand",
                "--out",
                "r.json",
            ]
        )
        == 0
    )
    capsys.readouterr()
    assert cli.main(["verify", "r.json", "--dataset", str(live_root)]) == 0
    assert "r.json: sound: 4 episodes of 2 policies replayed" in capsys.readouterr().out
    # A forger who claims a better last pose and OER, and makes the summary agree.
    data = json.loads(Path("r.json").read_text())
    episode = data["policies"]["LR"]["episodes"][1]
    episode["path"][-1][0] += 0.05
    episode["oer_tau"] = 1.0
    episode["reward"] = (1.0 - episode["oer_0"]) ** 2
    for name, policy in data["policies"].items():
        policy.update(session_metrics(policy["episodes"], ("oer_tau", "reward", "length", "oer_0", "refused"), 1))
        policy.pop("paired")
    Path("forged.json").write_text(json.dumps(EvaluationResults.model_validate(data).as_json()))
    assert cli.main(["verify", "forged.json", "--dataset", str(live_root)]) == 1
    out = capsys.readouterr().out
    assert "forged.json: not sound: LR session 0 episode 1: path[" in out and "replayed" in out, out
