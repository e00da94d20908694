"""The README's Table 4 block and docs/benchmark.md's run block are written from the run's records."""

from __future__ import annotations

import json
from pathlib import Path

from davis_ag.workflows.reproduce.configs import CONFIGS
from davis_ag.workflows.reproduce.pages.results import write_results_md
from davis_ag.workflows.reproduce.state import RunState, StageRecord
from results_factory import gap, results

SP_SCENES = ["Single-Strawberry/003", "b"]


def test_the_readme_block_beside_docs_is_rewritten_from_the_run(tmp_path: Path) -> None:
    # A results page in a project's docs/ writes the README's block too: no number copied by hand.
    (tmp_path / "docs").mkdir()
    readme = tmp_path / "README.md"
    readme.write_text("# p\n\nbefore\n<!-- results-table4:start -->\nstale .999\n<!-- results-table4:end -->\nafter\n")
    paired = gap(0.027, 0.01, 0.04, [("Single-Strawberry/003", -0.2, 22, 1)])
    oer = {"A2C": 0.6, "Rand": 0.45, "LRD": 0.44, "UDD": 0.3}
    state = RunState(results={"sp": results(oer, {"A2C": paired}, SP_SCENES)})
    page = write_results_md(tmp_path / "docs" / "results.md", CONFIGS["medium"], state, tmp_path).read_text()
    assert (
        "A2C minus `Best fixed action`: +.027, 95% bootstrap interval over episodes +.010 to +.040 (10,000 "
        "resamples), above zero. A2C is ahead on 0 of the 1 test scenes played (the table below)."
    ) in page
    assert "| Scene | Episodes | Distinct starts | A2C |" in page
    assert "| Single-Strawberry/003 | 22 | 1 | -.200 |" in page and "| ahead on | | | 0 of 1 |" in page
    text = readme.read_text()
    assert "stale" not in text and text.startswith("# p\n\nbefore\n") and text.endswith("after\n")
    assert "PPO" not in text and "PPO" not in page  # a run without PPO (medium's), whatever CONFIGS now lists
    assert (
        "| SP strawberry, ours (2 test scenes, split rule `scenes`) | .600 ± .010 | .440 ± .010 | .300 ± .010 "
        "| .450 ± .010 | – |"
    ) in text
    assert "(70/30 split by scene, seeded)" in page
    assert "| SP strawberry, paper (Table 4) | .520 ± .004 | .433 ± .007 | .371 ± .008 | .438 ± .101 | - |" in text
    assert "| MP vine, ours | not run yet |" in text and "| MP vine, paper (Table 4) | .369 ± .009 |" in text
    assert "SP strawberry: A2C > Rand ~ LRD > UDD **holds**." in text
    assert "SP strawberry +.027 (+.010 to +.040), ahead on 0 of the 1 test scenes played." in text
    # A page written elsewhere (a work folder beside the README) leaves the README alone.
    other = tmp_path / "work"
    other.mkdir()
    write_results_md(other / "results.md", CONFIGS["medium"], RunState(), other)
    assert readme.read_text() == text
    # So does another page in docs/ (a smaller run's, beside the headline's).
    write_results_md(tmp_path / "docs" / "results-medium.md", CONFIGS["medium"], RunState(), tmp_path)
    assert readme.read_text() == text


def test_the_readme_block_names_each_rows_split_rule(tmp_path: Path) -> None:
    # Issue 59: a row scored under the starts rule says so, beside the rows of the scenes rule.
    (tmp_path / "docs").mkdir()
    readme = tmp_path / "README.md"
    readme.write_text("<!-- results-table4:start -->\n<!-- results-table4:end -->\n")
    scored = results({"A2C": 0.6, "Rand": 0.45, "LRD": 0.44, "UDD": 0.3}, {}, SP_SCENES)
    scored.protocol.split_rule = "starts"
    page = write_results_md(
        tmp_path / "docs" / "results.md", CONFIGS["medium"], RunState(results={"sp": scored}), tmp_path
    )
    assert "| SP strawberry, ours (2 test scenes, split rule `starts`) |" in readme.read_text()
    assert (
        "split rule `starts`: 70/30 of each group's starts, seeded, train and test on the same scenes"
        in page.read_text()
    )


def test_the_blocks_beside_docs_give_the_train_gap_and_the_measured_hours(tmp_path: Path) -> None:
    # Issue 32: the README says how far each learner is from the best fixed action on train as on
    # test, and docs/benchmark.md which run results.md shows and the hours its stages took, all
    # from the run's records.
    docs = tmp_path / "docs"
    docs.mkdir()
    (tmp_path / "README.md").write_text("<!-- results-table4:start -->\n<!-- results-table4:end -->\n")
    (docs / "benchmark.md").write_text("a\n<!-- results-run:start -->\nold\n<!-- results-run:end -->\nb\n")
    (tmp_path / "models").mkdir()
    selection = {"kept_step": 90_000, "episodes": 200, "play": "sampled"}
    selection["scores"] = [{"step": 90_000, "oer_tau": 0.459}, {"step": 300_000, "oer_tau": 0.442}]
    (tmp_path / "models" / "a2c_sp-strawberry.training.json").write_text(json.dumps({"selection": selection}))
    fixed = {"up": {"oer_tau": 0.42, "reward": 0.0, "length": 3.0}}
    per_scene = [(f"Single-Strawberry/{i:03d}", g, 1, 1) for i, g in ((3, 0.1), (4, -0.1), (9, 0.2))]
    paired = gap(0.03, 0.02, 0.039, per_scene, scene_low=-0.1, scene_high=0.2)
    train = {"split": "train", "starts": 1280, "fixed_actions": fixed}
    oer = dict.fromkeys(("A2C", "Rand", "LRD", "UDD"), 0.45)
    result = results(oer, {"A2C": paired}, SP_SCENES, starts=507, train_split=train)
    state = RunState(
        results={"sp": result},
        stages={
            "sp-strawberry: generate": StageRecord(seconds=8460.0, note="86 scene(s)"),
            "sp-strawberry: validate": StageRecord(seconds=900.0, note="sound", check_seconds=330.0),
            "sp-strawberry: evaluate": StageRecord(seconds=36.0, note="split test"),
        },
    )
    sitting = {
        "started": "2026-11-25T01:45:02+00:00",
        "seconds": 36.0,
        "code": "x",
        "machine": "2 CPU cores (AMD EPYC), no GPU",
    }
    # Validation ran whole twice (its code changed between sittings): its cost is one whole check's.
    checks = [dict(sitting, seconds=540.0), dict(sitting, seconds=360.0)]
    clock = {"sp-strawberry: evaluate": [sitting], "sp-strawberry: validate": checks}
    (tmp_path / "clock.json").write_text(json.dumps({"stages": clock}))
    write_results_md(docs / "results.md", CONFIGS["paper-scale"], state, tmp_path)
    assert (
        "- A2C: SP strawberry +.030 (+.020 to +.039; over scenes -.100 to +.200, coarse with 3), ahead on 2 of "
        "the 3 test scenes played, train +.039." in (tmp_path / "README.md").read_text()
    )
    page = (docs / "results.md").read_text()
    assert (
        "Resampling the 3 test scenes played instead says little with so few: its 95% interval, -.100 to "
        "+.200, is about the range of their own gaps"
    ) in page
    # With enough test scenes the interval over them is the verdict on other scenes like them.
    from davis_ag.workflows.reproduce.pages.gaps import paired_line

    many = [(f"Single-Strawberry/{i:03d}", 0.1, 1, 1) for i in range(12)]
    wide = gap(0.03, 0.02, 0.039, many, scene_low=0.016, scene_high=0.048)
    line = paired_line(results(oer, {"A2C": wide}, [scene for scene, *_ in many]))
    assert line is not None
    assert line.endswith(
        "Resampling the 12 test scenes played instead (each with all its episodes: would the gap hold on other "
        "scenes like these?), the 95% interval is +.016 to +.048, above zero."
    )
    benchmark = (docs / "benchmark.md").read_text()
    assert benchmark.startswith("a\n<!-- results-run:start -->\n[results.md](results.md) shows the `paper-scale` run")
    assert "old" not in benchmark and benchmark.endswith("<!-- results-run:end -->\nb\n")
    assert "(Table 3's scenes and images): 86 SP strawberry and 44 MP vine scenes at 1280x720" in benchmark
    assert "evaluated on SP strawberry 2 test scenes, 507 eligible starts; MP vine not evaluated yet" in benchmark
    assert (
        "took 2.6 hours of wall time by the run's clock (SP strawberry: generate 2.35 h, validate 0.09 h (2 "
        "sittings, each doing it whole: 0.25 h in all), evaluate 0.01 h; MP vine: no stage finished yet), "
        "on 2 CPU cores (AMD EPYC), no GPU; results.md" in benchmark
    )
    assert (
        "| sp-strawberry: validate | 900 | 0.25 | 2 CPU cores (AMD EPYC), no GPU | unrecorded | sound; 2 sittings on "
        "the run's clock, each doing the whole validate again (its code changed, or a sitting was stopped): one "
        "whole validate took 0.09 h |" in page
    )
