"""``davis-ag reproduce``: a resumed run's progress starts at its checkpoint, the configurations
table follows the code, an evaluation gets the train-split yardstick."""

from __future__ import annotations

from pathlib import Path

import pytest
from stable_baselines3.common.callbacks import CallbackList

from davis_ag.benchmark.progress import TrainingProgress
from davis_ag.benchmark.training import train_a2c
from kill_callback import KillAfter
from layout_factory import write_tiny_dataset


def test_progress_of_a_resumed_run_starts_at_its_checkpoint(tmp_path: Path, one_thread: None) -> None:
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    kwargs = dict(
        total_timesteps=160,
        seed=1,
        out_path=tmp_path / "a2c",
        n_envs=2,
        arch="pooled",
        device="cpu",
        checkpoint_every=40,
    )
    with pytest.raises(KeyboardInterrupt):
        train_a2c(
            root, "sp", callback=CallbackList([TrainingProgress(160, "t"), KillAfter(90)]), progress=False, **kwargs
        )
    resumed = TrainingProgress(160, "t")
    train_a2c(root, "sp", callback=resumed, progress=False, **kwargs)
    # 80 steps came from the checkpoint and 80 from this sitting: the count ends at the total,
    # where it used to end at 80 ("80 of 160 steps" for a finished run).
    assert resumed.steps == 160


def test_the_configurations_table_in_the_docs_is_the_codes() -> None:
    # docs/benchmark.md's table of `reproduce --config` sizes follows CONFIGS, never a hand copy.
    from davis_ag.workflows.reproduce.configs import CONFIGS, CONFIGS_MARKER, configurations_table

    page = (Path(__file__).resolve().parents[3] / "docs" / "benchmark.md").read_text()
    section = page.split(f"<!-- {CONFIGS_MARKER}:start -->\n", 1)[1].split(f"\n<!-- {CONFIGS_MARKER}:end -->", 1)[0]
    assert section == configurations_table(), (
        'docs/benchmark.md is behind CONFIGS; rewrite it: python -c "from davis_ag.atomic_files import '
        "write_marked_section as w; from davis_ag.workflows.reproduce import configs as r; "
        "w('docs/benchmark.md', r.CONFIGS_MARKER, r.configurations_table())\""
    )
    # Issue 22: medium's MP split keeps at least 3 test scenes (70/30 of 10 or more).
    assert CONFIGS["medium"].mp_scenes >= 10 and "| `medium` | 10 scenes | 10 scenes," in section


def test_an_evaluation_gets_the_train_split_yardstick_once(sp_root: Path) -> None:
    # A reused evaluation from before the yardstick gets it; one that has it is not recomputed.
    from davis_ag.benchmark import evaluate
    from davis_ag.benchmark.exact import split_fixed_actions
    from davis_ag.workflows.reproduce.run import add_train_split
    from davis_ag.workflows.reproduce.state import without_episodes

    results = evaluate([], sp_root, "sp", sessions=1, episodes=2, baselines=["Rand"])
    assert results.train_split is None
    assert add_train_split(results, sp_root, "sp", "strawberry")
    assert results.train_split is not None
    assert results.train_split.model_dump(exclude_none=True) == split_fixed_actions(
        sp_root, "sp", "train", "strawberry"
    )
    assert not add_train_split(results, sp_root, "sp", "strawberry")
    # The run's state keeps it with the evaluation, for the page.
    assert without_episodes(results).train_split == results.train_split


def test_a_run_the_disk_cannot_hold_is_refused_before_anything_is_written(tmp_path: Path) -> None:
    # Issue 32: paper-scale writes about 48 GB of views and 21 GB of observation caches.
    from dataclasses import replace

    from davis_ag.errors import UserError
    from davis_ag.workflows.reproduce.configs import CONFIGS, disk_needed
    from davis_ag.workflows.reproduce.run import reproduce

    paper = CONFIGS["paper-scale"]
    # Table 3's 86 SP strawberry and 44 MP vine scenes (285 and 1,800 views, Table 2) at 1280x720.
    views = 86 * 285 + 44 * 1800
    assert 0.4e6 * views < disk_needed(paper) < 0.5e6 * views + 224 * 224 * 4 * views
    huge = replace(paper, name="huge", sp_scenes=10**7)
    out = tmp_path / "out"
    with pytest.raises(UserError, match=r"needs about .* GB more under .* GB free: free space, or pass --out"):
        reproduce(huge, out, tmp_path / "results.md")
    assert not out.exists() and not (tmp_path / "results.md").exists()


def test_the_status_of_a_run_stopped_in_its_first_stage_says_where_it_stands(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A crops run's first stage (ten apple trees grown and drawn) takes half an hour: ``--status``
    answered "no reproduce run started there" all that while, as after a kill in it."""
    from davis_ag.workflows import stages
    from davis_ag.workflows.reproduce import run as reproduce_run
    from davis_ag.workflows.reproduce.configs import CONFIGS
    from davis_ag.workflows.reproduce.run import reproduce
    from davis_ag.workflows.reproduce.status import run_status

    def killed(*args: object, **kwargs: object) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(stages, "generate_scenes", killed)
    # The crops run asks for 26 GB before it writes: a CI disk with less refused the run before its
    # first stage and the test never reached the status it checks (the refusal has its own test above).
    monkeypatch.setattr(reproduce_run, "check_disk", lambda *args, **kwargs: None)
    out = tmp_path / "run"
    with pytest.raises(KeyboardInterrupt):
        reproduce(CONFIGS["crops"], out, tmp_path / "crops.md")
    config, status = run_status(out)
    assert config == CONFIGS["crops"]
    first = status[0]
    assert (first.stage, first.done, first.progress) == ("sp-apple: generate", False, "not started")
    assert not any(s.done for s in status)


#: PPO at a test's size: a rollout of 16 steps per environment instead of the zoo's 128.
SHORT_PPO = {"n_steps": 16, "batch_size": 32}


def test_ppo_trains_beside_a2c_resumes_a_killed_run_and_reuses_a_finished_one(
    tmp_path: Path, sp_root: Path, one_thread: None, capsys: pytest.CaptureFixture[str]
) -> None:
    # Issue 32: reproduce trains PPO with A2C's budget; a killed PPO run resumes from its
    # checkpoint, a finished one is reused, and A2C's models of before PPO stay reusable.
    import json
    from dataclasses import replace

    from davis_ag.benchmark.algorithms import A2C_SETTINGS, SB3_SETTINGS
    from davis_ag.benchmark.training import training_record_path
    from davis_ag.workflows.reproduce.configs import CONFIGS
    from davis_ag.workflows.reproduce.learners import KEEP, learner_stamp, model_path, train_learner

    assert CONFIGS["paper-scale"].learners == ("a2c", "ppo")
    # A2C's stamp is the one models made before PPO carry, so they are not trained again.
    assert learner_stamp("a2c", 300_000) == {"timesteps": 300_000, "a2c_settings": A2C_SETTINGS, "keep": KEEP}
    config = replace(CONFIGS["small"], n_envs=2, seed=1)
    model = model_path(tmp_path, "sp-strawberry", "ppo")
    assert model.name == "ppo_sp-strawberry.zip"
    kwargs = dict(settings=SHORT_PPO, arch="pooled", checkpoint_every=32, progress=False)
    with pytest.raises(KeyboardInterrupt):
        train_learner("ppo", sp_root, "sp", "strawberry", model, 128, config, callback=KillAfter(70), **kwargs)
    assert not model.exists()
    assert train_learner("ppo", sp_root, "sp", "strawberry", model, 128, config, **kwargs) is not None
    assert "resuming ppo_sp-strawberry.zip from its checkpoint at 64 of 128 steps" in capsys.readouterr().out
    record = json.loads(training_record_path(model).read_text())
    assert record["algorithm"] == "PPO" and record["timesteps"] == 128 and record["keep"] == "best-train"
    assert (
        record["sb3_settings"] == {**SB3_SETTINGS["ppo"], **SHORT_PPO}
        and record["seed"] == 1
        and len(record["sittings"]) == 2
    )
    made = model.stat().st_mtime_ns
    assert train_learner("ppo", sp_root, "sp", "strawberry", model, 128, config, **kwargs) is None
    assert model.stat().st_mtime_ns == made
    # A run of another seed or number of environments does not reuse it: its page would state them.
    config = replace(config, seed=2)
    assert train_learner("ppo", sp_root, "sp", "strawberry", model, 128, config, **kwargs) is not None
    record = json.loads(training_record_path(model).read_text())
    assert record["seed"] == 2
    assert train_learner("ppo", sp_root, "sp", "strawberry", model, 128, config, **kwargs) is None
    # A model trained on another train split (the group grew since) is trained anew, not reused.
    record_path = training_record_path(model)
    record_path.write_text(json.dumps({**record, "train_scenes": ["Single-Strawberry/001"]}))
    assert train_learner("ppo", sp_root, "sp", "strawberry", model, 128, config, **kwargs) is not None
    assert json.loads(record_path.read_text())["train_scenes"] == ["Single-Strawberry/000"]
    # Another budget is another model: trained anew, not reused.
    assert train_learner("ppo", sp_root, "sp", "strawberry", model, 96, config, **kwargs) is not None


SP_ONLY = (("sp", "strawberry"),)


@pytest.mark.slow
def test_a_whole_run_times_every_stage_on_its_clock_and_a_rerun_adds_no_sitting(
    tmp_path: Path, one_thread: None, capsys: pytest.CaptureFixture[str]
) -> None:
    """``reproduce`` end to end at the smallest size (SP strawberry, A2C with the paper's network;
    PPO's stage is the same code, trained in the test above): every stage that worked is on the
    clock and in the page's stage table; a second sitting over the finished run reuses everything,
    its validation included, and adds no sitting to any stage; a file changed since is validated
    again."""
    import json
    from dataclasses import replace

    from davis_ag.provenance import machine_summary
    from davis_ag.workflows.reproduce.clock import CLOCK_FILE, read_clock
    from davis_ag.workflows.reproduce.configs import CONFIGS
    from davis_ag.workflows.reproduce.run import reproduce
    from davis_ag.workflows.reproduce.status import run_status

    config = replace(
        CONFIGS["small"],
        name="tiny",
        size=(160, 90),
        sp_scenes=2,  # one to train on, one to test on
        sp_timesteps=256,
        n_envs=2,
        episodes=4,
        sessions=1,
        learners=("a2c",),
    )
    out, page = tmp_path / "run", tmp_path / "results.md"
    assert reproduce(config, out, page, SP_ONLY) == 0
    clock = read_clock(out / CLOCK_FILE)
    worked = [f"sp-strawberry: {stage}" for stage in ("generate", "validate", "train A2C", "evaluate")]
    assert sorted(clock) == sorted(worked) and all(len(clock[s]) == 1 for s in worked)
    state = json.loads((out / "state.json").read_text())
    for stage in worked:
        assert state["stages"][stage]["seconds"] == pytest.approx(clock[stage][0]["seconds"], abs=0.2)
        seconds = clock[stage][0]["seconds"]
        # Issue 32: the page says where each stage ran.
        assert clock[stage][0]["machine"] == machine_summary()
        assert f"| {stage} | {seconds:.0f} | {seconds / 3600:.2f} | {machine_summary()} |" in page.read_text()
    # One whole check's own time, which the clock cannot tell apart once a changed validator repeats it.
    check = state["stages"]["sp-strawberry: validate"]["check_seconds"]
    assert 0 < check <= clock["sp-strawberry: validate"][0]["seconds"] + 0.2
    sp_stages = [s for s in run_status(out)[1] if s.stage.startswith("sp-")]
    assert all(s.done for s in sp_stages) and [s.stage for s in sp_stages] == [
        f"sp-strawberry: {stage}" for stage in ("generate", "validate", "train A2C", "evaluate")
    ]
    capsys.readouterr()
    assert reproduce(config, out, page, SP_ONLY) == 0
    assert read_clock(out / CLOCK_FILE) == clock
    rerun = capsys.readouterr().out
    assert "(validated before; its files and the validator are unchanged)" in rerun
    assert json.loads((out / "state.json").read_text())["stages"] == state["stages"]
    view = next((out / "dataset" / "Single-Strawberry" / "001" / "images").glob("*.jpeg"))
    view.write_bytes(view.read_bytes()[: view.stat().st_size // 2])  # cut short since
    assert reproduce(config, out, page, SP_ONLY) == 1
    assert "validated before" not in capsys.readouterr().out


def test_an_edited_evaluation_of_a_run_is_not_written_into_its_page(sp_root: Path, tmp_path: Path) -> None:
    """A run reuses its evaluation's JSON at every sitting: one whose summary was edited is refused
    in one line (and left where it is) rather than shown on the page."""
    import json

    from davis_ag.benchmark import evaluate
    from davis_ag.errors import UserError
    from davis_ag.workflows.reproduce.configs import CONFIGS
    from davis_ag.workflows.reproduce.run import _reusable_results

    config = CONFIGS["small"]
    path = evaluate([], sp_root, "sp", sessions=config.sessions, episodes=4, seed=config.seed).write(
        tmp_path / "r.json"
    )
    data = json.loads(path.read_text())
    data["policies"]["Rand"]["oer_tau"]["mean"] = 0.999
    path.write_text(json.dumps(data))
    with pytest.raises(UserError, match=r"Rand's oer_tau.mean is 0.999 .* move it aside") as refused:
        _reusable_results(path, [], "test", ["Single-Strawberry/001"], config)
    assert "\n" not in str(refused.value) and json.loads(path.read_text()) == data
