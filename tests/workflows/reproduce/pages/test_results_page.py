"""docs/results.md is written from the run's records: the orderings, the scenes' code, the sittings."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from davis_ag.workflows.reproduce.configs import CONFIGS
from davis_ag.workflows.reproduce.pages.paper_table4 import PAPER_ORDERINGS, PaperCell, ordering_failures
from davis_ag.workflows.reproduce.pages.results import write_results_md
from davis_ag.workflows.reproduce.state import RunState, StageRecord, without_episodes
from results_factory import results as made_results


def write_scene(root: Path, folder: str, version: str, plants: str | None = None) -> None:
    scene = root / "dataset" / folder
    scene.mkdir(parents=True)
    meta = {
        "generator": {"version": version},
        "camera": {"width": 640, "height": 360},
        "renderer": {"name": "opengl", "look": "default", "antialiasing": "4x multisampled colour"},
    }
    if plants is not None:
        meta["plant_generator"] = plants
    (scene / "scene.json").write_text(json.dumps(meta))


def test_a_run_resumed_across_code_changes_says_so(tmp_path: Path) -> None:
    folders = ["Single-Strawberry/000", "Single-Strawberry/001"]
    write_scene(tmp_path, folders[0], "0.1.0+aaaa")
    write_scene(tmp_path, folders[1], "0.1.0+bbbb")
    (tmp_path / "models").mkdir()
    record = {
        "timesteps": 300_000,
        "seconds": 7200.0,
        "steps_per_second": 41.7,
        "arch": "paper",
        "n_envs": 8,
        "sittings": [
            {"code": "0.1.0+aaaa", "from_step": 0, "to_step": 120_000, "seconds": 3000.0},
            {"code": "0.1.0+bbbb", "from_step": 120_000, "to_step": 300_000, "seconds": 4200.0},
        ],
    }
    (tmp_path / "models" / "a2c_sp-strawberry.training.json").write_text(json.dumps(record))
    oer = {"A2C": 0.6, "Rand": 0.45, "LRD": 0.44, "UDD": 0.3}
    state = RunState(
        scene_folders={"sp-strawberry": folders},
        results={"sp": made_results(oer, scenes=folders[1:])},
        # What a resuming sitting (code bbbb) leaves in state.json: it re-records the generate
        # stage it only skipped, and times only its own part of the training.
        stages={
            "sp-strawberry: generate": StageRecord(seconds=12.0, note="2 scenes", code="0.1.0+bbbb"),
            "sp-strawberry: train A2C": StageRecord(
                seconds=4200.0, note="300000 steps, 71.4 steps/s", code="0.1.0+bbbb"
            ),
        },
    )
    text = write_results_md(tmp_path / "results.md", CONFIGS["medium"], state, tmp_path).read_text()
    assert "0.1.0+aaaa (1 scene); 0.1.0+bbbb (1 scene) — made by more than one version of the code" in text
    assert "300,000 steps in 2 sitting(s)" in text and "the code changed between sittings" in text
    assert "**holds** in this run:" in text  # .6 > .45 ~ .44 > .3
    assert "nor does it hold in Table 4's own numbers" not in text  # Table 4 meets its own ordering
    assert "under-trained" not in text  # 300K steps: the paper's count
    assert "do not edit by hand" in text and "How this run was made" in text
    # The stage table takes each stage's code from what did the work: the scenes, the sittings.
    assert "| sp-strawberry: generate | 12 | 0.00 | - | 0.1.0+aaaa (1 scene); 0.1.0+bbbb (1 scene) | 2 scenes |" in text
    assert (
        "| sp-strawberry: train A2C | 7200 | 2.00 | - | 0.1.0+aaaa, 0.1.0+bbbb | 300,000 steps in 2 sitting(s), "
        "41.7 steps/s over the sittings' wall time |"
    ) in text
    assert "71.4" not in text and "| total | 7212 | 2.00 | | | |" in text


def test_how_the_run_was_made_names_the_plants_and_the_a2c_settings(tmp_path: Path) -> None:
    # Issue 22: the page says which plant generator made the scenes and how A2C was set up.
    folders = ["Single-Strawberry/000", "Single-Strawberry/001", "Single-Strawberry/002"]
    write_scene(tmp_path, folders[0], "0.1.0+aaaa", plants="canopy")
    write_scene(tmp_path, folders[1], "0.1.0+aaaa", plants="canopy")
    write_scene(tmp_path, folders[2], "0.1.0+aaaa")  # from before scene.json recorded its plants
    (tmp_path / "models").mkdir()
    record = {
        "timesteps": 300_000,
        "seconds": 6000.0,
        "steps_per_second": 50.0,
        "arch": "paper",
        "n_envs": 8,
        "a2c_settings": {"ent_coef": 0.01, "normalize_advantage": True},
        "sittings": [{"code": "0.1.0+aaaa", "from_step": 0, "to_step": 300_000, "seconds": 6000.0}],
    }
    (tmp_path / "models" / "a2c_sp-strawberry.training.json").write_text(json.dumps(record))
    state = RunState(scene_folders={"sp-strawberry": folders})
    text = write_results_md(tmp_path / "results.md", CONFIGS["medium"], state, tmp_path).read_text()
    how = text.split("## How this run was made", 1)[1]
    assert "plants grown by `--plants canopy` (2 scenes); `--plants architecture` (1 scene)" in how
    assert "settings ent_coef=0.01, normalize_advantage=True over SB3's A2C defaults" in how
    assert "kept the last snapshot" in how  # a record from before snapshots were scored
    record["selection"] = {
        "rule": "best-train",
        "every": 10_000,
        "episodes": 200,
        "play": "sampled",
        "kept_step": 120_000,
        "scores": [{"step": 120_000, "oer_tau": 0.561}, {"step": 300_000, "oer_tau": 0.437}],
    }
    (tmp_path / "models" / "a2c_sp-strawberry.training.json").write_text(json.dumps(record))
    how = write_results_md(tmp_path / "results.md", CONFIGS["medium"], state, tmp_path).read_text()
    assert (
        "kept the snapshot at 120,000 steps, the best of 2 scored on the train split (200 sampled "
        "episodes each, every 10,000 steps): train OER_tau 0.561, the last snapshot's 0.437"
    ) in how
    head = text.split("## How this run was made", 1)[0]
    assert "SB3 defaults" not in head and "A2C not evaluated yet" in head  # no play before an evaluation


def test_the_kept_snapshot_is_set_beside_the_best_fixed_action_on_train(tmp_path: Path) -> None:
    # Issue 22: a learner that beats one move on its own scenes but not on test is told apart from
    # one that learned nothing; the numbers come from the training record and the evaluation's JSON.
    from davis_ag.workflows.reproduce.pages.policies import train_split_line, train_split_references

    (tmp_path / "models").mkdir()
    record = {
        "selection": {
            "rule": "best-train",
            "every": 10_000,
            "episodes": 200,
            "play": "sampled",
            "kept_step": 240_000,
            "scores": [{"step": 240_000, "oer_tau": 0.565}, {"step": 300_000, "oer_tau": 0.444}],
        }
    }
    (tmp_path / "models" / "a2c_sp-strawberry.training.json").write_text(json.dumps(record))
    fixed = {a: {"oer_tau": v, "reward": 0.0, "length": 3.0} for a, v in (("up", 0.41), ("backward", 0.434))}
    train = {"split": "train", "starts": 176, "fixed_actions": fixed}
    result = made_results({"A2C": 0.5}, train_split=train)
    assert str(train_split_line("sp", result, tmp_path)).startswith(
        "On the train split (176 eligible starts), where the snapshot was chosen: A2C's kept snapshot "
        "(240,000 steps) scores OER_tau .565 (200 sampled episodes), the best fixed action there (always "
        "`backward`) .434 exactly, .131 above it; the last snapshot (300,000 steps) .444."
    )
    assert result.train_split is not None
    result.train_split.fixed_actions["backward"]["oer_tau"] = 0.6
    assert ".035 below it" in str(train_split_line("sp", result, tmp_path))
    # Without the yardstick (an evaluation from before it) or a scored run, no line.
    before = made_results({"A2C": 0.5})
    assert train_split_line("sp", before, tmp_path) is None
    assert train_split_line("mp", result, tmp_path) is None
    # The same yardstick is drawn across the learning curve's snapshot panel.
    assert train_split_references({"sp": result, "mp": before}) == {
        "sp-strawberry: best fixed action (always backward), exact": 0.6
    }


def test_a_broken_ordering_names_the_steps_that_break() -> None:
    # Our medium run's SP numbers: A2C .405 > Rand .388, but Rand and LRD are .030 apart with
    # stds .003 and .002, and UDD .360 is above LRD .358.
    stats = {
        name: PaperCell(m, sd)
        for name, m, sd in (("A2C", 0.405, 0.002), ("Rand", 0.388, 0.003), ("LRD", 0.358, 0.002), ("UDD", 0.360, 0.005))
    }
    assert ordering_failures(PAPER_ORDERINGS["sp"], stats) == [
        "Rand ~ LRD fails: .388 and .358 are .030 apart, more than their stds added (.005)",
        "LRD > UDD fails: .358 is not above .360",
    ]
    assert ordering_failures(PAPER_ORDERINGS["mp"], stats) == []  # A2C > Rand > LRD ~ UDD


def test_the_page_shows_what_each_policy_does(tmp_path: Path, sp_root: Path, one_thread: None) -> None:
    # A real (tiny) run's records: a model, its training record, an evaluation with every row.
    from davis_ag.benchmark.algorithms import A2C_SETTINGS
    from davis_ag.benchmark.training import train_a2c
    from davis_ag.workflows.stages import run_baselines

    (tmp_path / "docs").mkdir()
    model = train_a2c(
        sp_root,
        "sp",
        total_timesteps=60,
        seed=0,
        out_path=tmp_path / "models" / "a2c_sp-strawberry",
        n_envs=2,
        arch="pooled",
        device="cpu",
        checkpoint_every=0,
    )
    results = run_baselines(sp_root, "sp", "strawberry", "test", 20, 3, model=model)
    results.write(tmp_path / "results" / "sp-strawberry.json")
    state = RunState(results={"sp": without_episodes(results)})
    page = tmp_path / "docs" / "results.md"
    text = write_results_md(page, CONFIGS["medium"], state, tmp_path).read_text()
    policies = results.policies
    best = policies["Best fixed action"]
    assert best.action in results.protocol.actions and policies["A2C"].play == "sampled"
    assert "| Best fixed action |" in text and f"(always `{best.action}`)" in text
    assert "A2C **beats** it" in text or "A2C **does not beat** it" in text
    assert ", ".join(f"{k}={v}" for k, v in A2C_SETTINGS.items()) in text
    assert "plays actions sampled from the policy" in text
    assert "uniform over every eligible (view, target) pair" in text
    # Exact beside sampled, and each policy's action shares.
    lrd = policies["LRD"]
    assert lrd.exact is not None
    assert f"| LRD | {_c(lrd.oer_tau.mean)} ± {_c(lrd.oer_tau.sem)} | {_c(lrd.exact['oer_tau'])} |" in text
    assert "| Policy | forward | backward | left | right | up | down | done |" in text
    # The episodes' drawn starts beside every start's mean OER_0 (always `done` ends where it starts).
    assert results.fixed_actions is not None
    assert (
        f"Mean start OER (OER_0) of these episodes: {_c(lrd.oer_0.mean)}, against "
        f"{_c(results.fixed_actions['done']['oer_tau'])} over every eligible start of the split (exact)"
    ) in text
    # Played as the benchmark plays it (sampled), the trained A2C is not one move repeated.
    played = policies["A2C"].action_counts or {}
    shares = np.array(list(played.values())) / sum(played.values())
    assert (shares >= 0.05).sum() >= 2, played
    counts = best.action_counts or {}
    assert "| Best fixed action | " + " | ".join("100" if a == best.action else "0" for a in counts) + " |" in text
    for picture in (
        "results-sp-strawberry-actions.png",
        "results-learning-curve.png",
        "results-sp-strawberry-scene-gaps.png",
    ):
        assert f"(images/{picture})" in text and (tmp_path / "docs" / "images" / picture).is_file()
    assert "PPO" not in text  # this run trained A2C only
    # Another run's page beside it (a smaller run's, a split rule's) draws its own pictures and
    # leaves this page's alone.
    drawn = {p.name: p.read_bytes() for p in (tmp_path / "docs" / "images").iterdir()}
    other = write_results_md(tmp_path / "docs" / "results-medium.md", CONFIGS["medium"], state, tmp_path).read_text()
    for picture in drawn:
        own = picture.replace("results-", "results-medium-", 1)
        assert f"(images/{own})" in other and (tmp_path / "docs" / "images" / own).is_file()
        assert (tmp_path / "docs" / "images" / picture).read_bytes() == drawn[picture]


def test_a_run_with_ppo_shows_its_row_gap_settings_and_stage(tmp_path: Path, sp_root: Path, one_thread: None) -> None:
    # Issue 32: PPO trained beside A2C is a row of the same evaluation; adding it leaves the other
    # rows as they were, and the page and README give its paired gap as they give A2C's.
    from dataclasses import replace

    from davis_ag.benchmark.training import train_agent
    from davis_ag.figures.result_charts import plot_results
    from davis_ag.workflows.reproduce.learners import model_path
    from davis_ag.workflows.reproduce.run import _reusable_results, add_train_scores, add_train_split
    from davis_ag.workflows.stages import run_baselines

    (tmp_path / "docs").mkdir()
    (tmp_path / "README.md").write_text("<!-- results-table4:start -->\n<!-- results-table4:end -->\n")
    (tmp_path / "dataset").symlink_to(sp_root)
    models = {}
    for algo, settings in (("a2c", "ours"), ("ppo", {"n_steps": 16, "batch_size": 32})):
        models[algo] = train_agent(
            sp_root,
            "sp",
            total_timesteps=64,
            seed=0,
            out_path=model_path(tmp_path, "sp-strawberry", algo),
            n_envs=2,
            arch="pooled",
            device="cpu",
            checkpoint_every=0,
            algo=algo,
            settings=settings,
            progress=False,
        )
    before = run_baselines(sp_root, "sp", "strawberry", "test", 20, 3, model=models["a2c"])
    both = run_baselines(sp_root, "sp", "strawberry", "test", 20, 3, model=models["a2c"], learners=(models["ppo"],))
    assert set(both.policies) - set(before.policies) == {"PPO"}
    for name, row in before.policies.items():  # seeded episodes: the rows of before PPO, unchanged
        assert both.policies[name] == row, name
    # An evaluation from before PPO is not reused for a run that trains it.
    results_json = tmp_path / "results" / "sp-strawberry.json"
    before.write(results_json)
    config = replace(CONFIGS["small"], episodes=20, sessions=3)
    test_scenes = ["Single-Strawberry/001"]
    assert _reusable_results(results_json, [models["a2c"]], "test", test_scenes, config) is not None
    assert _reusable_results(results_json, [models["a2c"], models["ppo"]], "test", test_scenes, config) is None
    both.write(results_json)
    assert _reusable_results(results_json, [models["a2c"], models["ppo"]], "test", test_scenes, config) is not None
    # A group that grew has another test split: evaluated anew.
    grown = [*test_scenes, "Single-Strawberry/002"]
    assert _reusable_results(results_json, [models["a2c"], models["ppo"]], "test", grown, config) is None
    assert plot_results(both, results_json.with_suffix(".png")).is_file()  # the stage's chart, PPO's bar in it
    add_train_split(both, sp_root, "sp", "strawberry")
    # The kept snapshots scored again on fresh train episodes, as on test: their selection scores run high.
    assert add_train_scores(both, sp_root, "sp", "strawberry", models, config)
    assert not add_train_scores(both, sp_root, "sp", "strawberry", models, config)  # scored once
    assert both.train_split is not None
    fresh = both.train_split.learners
    assert fresh is not None
    assert set(fresh) == {"A2C", "PPO"} and all(0 <= f.oer_tau.mean <= 1 for f in fresh.values())
    assert fresh["A2C"].sessions == 3 and fresh["A2C"].episodes == 20

    state = RunState(
        scene_folders={"sp-strawberry": ["Single-Strawberry/000", "Single-Strawberry/001"]},
        results={"sp": without_episodes(both)},
        stages={
            "sp-strawberry: train A2C": StageRecord(seconds=1.0, note="64 steps", code="x"),
            "sp-strawberry: train PPO": StageRecord(seconds=1.0, note="64 steps", code="x"),
        },
    )
    text = write_results_md(tmp_path / "docs" / "results.md", config, state, tmp_path).read_text()
    ppo = both.policies["PPO"]
    assert f"| PPO | {_c(ppo.oer_tau.mean)} ± {_c(ppo.oer_tau.std)} | – |" in text
    gap = ppo.paired["Best fixed action"]  # the evaluation's own, on the same episodes
    assert state.results["sp"].policies["PPO"].paired["Best fixed action"] == gap
    ahead = sum(s.gap > 0 for s in gap.per_scene)
    assert f"PPO minus `Best fixed action`: {'+' if gap.gap >= 0 else '-'}{_c(abs(gap.gap))}" in text
    assert f"PPO is ahead on {ahead} of the 1 test scenes played" in text and "A2C is ahead on" in text
    assert "PPO: trained with n_steps=16, n_epochs=4, batch_size=32, learning_rate=lin_2.5e-4" in text
    assert "PPO beside it (RL Baselines3 Zoo's Atari settings" in text
    # Beside PPO, A2C's curve says it is A2C's.
    assert "- sp-strawberry (A2C): rolling mean" in text and "- sp-strawberry (PPO): rolling mean" in text
    train_starts = both.train_split.starts
    assert (
        f"Split `test` (1 scene(s), {both.protocol.starts:,} eligible starts; the train split: "
        f"{train_starts:,} eligible starts), tau = 3" in text
    )
    assert "where the snapshot was chosen: A2C's kept snapshot (70 steps)" in text
    assert f"scores OER_tau {_c(fresh['A2C'].oer_tau.mean)} (3 x 20 fresh episodes, as on test; " in text
    assert "where the snapshot was chosen: PPO's kept snapshot (64 steps)" in text
    how = text.split("## How this run was made", 1)[1]
    assert "  - A2C: 70 steps in 1 sitting(s)" in how and "  - PPO: 64 steps in 1 sitting(s)" in how
    assert "over SB3's PPO defaults" in how
    assert "| sp-strawberry: train PPO |" in text and "| sp-strawberry: train A2C |" in text
    readme = (tmp_path / "README.md").read_text()
    assert "| | A2C | PPO (ours only) | LRD |" in readme and "paper (Table 4) | .520 ± .004 | - | .433" in readme
    assert "Each learner minus `Best fixed action` on the same test episodes" in readme
    assert "\n- A2C: SP strawberry " in readme and "\n- PPO: SP strawberry " in readme


def _c(value: float) -> str:
    text = f"{value:.3f}"
    return text[1:] if text.startswith("0.") else text
