"""The ``a2c-search`` run: candidates trained and scored on the train split only, a finished one
reused, the page between its markers with every candidate beside Rand and the Best fixed action,
``--status`` and ``--rewrite-results`` on such a run."""

from __future__ import annotations

import json
import os
from dataclasses import asdict, replace
from pathlib import Path

import pytest

from davis_ag.benchmark.results import load_results
from davis_ag.benchmark.tvm import TVMEnv
from davis_ag.errors import UserError
from davis_ag.workflows.reproduce.a2c_candidates import (
    CANDIDATES,
    Candidate,
    candidate_model,
    candidates_of,
    results_path,
)
from davis_ag.workflows.reproduce.a2c_search import check_page, evaluate_on_train, train_candidate
from davis_ag.workflows.reproduce.configs import CONFIGS
from davis_ag.workflows.reproduce.pages.a2c_search import write_search_page
from davis_ag.workflows.reproduce.run import stage_recorder
from davis_ag.workflows.reproduce.state import RunState
from layout_factory import write_tiny_dataset

#: The search at a test's size: our A2C, the zoo's (with its own 16 environments) and PPO with a
#: short rollout, each a few dozen steps of the small network.
TINY = (
    CANDIDATES[0],
    Candidate("ppo-zoo-atari", "PPO zoo-atari", "ppo", "ours", "the target", over={"n_steps": 16, "batch_size": 32}),
    next(c for c in CANDIDATES if c.key == "a2c-zoo-atari"),
)
TRAIN = {"arch": "pooled", "progress": False, "checkpoint_every": 0, "select_every": 0}


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory):
    """The search's stages on two tiny scenes (000 trains, 001 tests), every environment made
    meanwhile recorded by its split."""
    import torch

    from davis_ag.provenance import code_version
    from davis_ag.workflows.reproduce.clock import CLOCK_FILE, StageClock

    out = tmp_path_factory.mktemp("a2c-search")
    write_tiny_dataset(out / "dataset", "sp", "strawberry", scenes=2)
    config = replace(CONFIGS["a2c-search"], sp_scenes=2, sp_timesteps=48, n_envs=2, episodes=12, sessions=1)
    state = RunState()
    state.config = json.loads(json.dumps(asdict(config)))
    state.save(out / "state.json")
    record = stage_recorder(state, out / "state.json")
    clock = StageClock(out / CLOCK_FILE, code_version())
    splits: list[str] = []
    made = TVMEnv.__init__

    def recording(self, *args, **kwargs):
        splits.append(kwargs.get("split", args[2] if len(args) > 2 else "train"))
        made(self, *args, **kwargs)

    threads = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(TVMEnv, "__init__", recording)
            first = evaluate_on_train(config, out, TINY, record)  # the yardsticks, before any candidate
            for candidate in TINY:
                train_candidate(config, out, candidate, clock, record, **TRAIN)
            results = evaluate_on_train(config, out, TINY, record)
    finally:
        torch.set_num_threads(threads)
    return out, config, state, record, clock, splits, first, results


def test_the_configuration_searches_sp_strawberrys_train_split_beside_ppo() -> None:
    config = CONFIGS["a2c-search"]
    assert config.page == "a2c-search" and config.pairs == (("sp", "strawberry"),) and config.sp_scenes == 10
    presets = {(c.algo, c.preset) for c in candidates_of(config)}
    assert presets == {("a2c", "ours"), ("a2c", "sb3"), ("a2c", "zoo-atari"), ("ppo", "ours")}
    assert {c.timesteps(config) for c in candidates_of(config)} == {300_000}  # the longer budget is paper-scale's
    assert len({c.key for c in CANDIDATES}) == len({c.row(config) for c in CANDIDATES}) == len(CANDIDATES)


def test_the_paper_scale_search_reads_the_table4_dataset_and_tries_the_longer_budget_first() -> None:
    """Its group is the paper-scale run's (so a link shares the dataset), its rule the starts run's,
    and its 300K rows are trained exactly as that run trains A2C and PPO (so their models reuse)."""
    from davis_ag.workflows.reproduce.learners import learner_stamp

    config, table4 = CONFIGS["a2c-search-paper-scale"], CONFIGS["paper-scale"]
    assert config.page == "a2c-search" and config.split_rule == "starts"
    assert (config.size, config.sp_scenes, config.seed, config.pairs[0]) == (
        table4.size,
        table4.sp_scenes,
        table4.seed,
        table4.pairs[0],
    )
    candidates = candidates_of(config)
    assert [(c.algo, c.timesteps(config)) for c in candidates] == [
        ("a2c", 1_000_000),
        ("a2c", 300_000),
        ("ppo", 300_000),
    ]
    for candidate in candidates[1:]:
        ours = learner_stamp(candidate.algo, candidate.timesteps(config), candidate.settings())
        assert ours == learner_stamp(candidate.algo, table4.sp_timesteps)
    assert len({c.key for c in candidates}) == len({c.row(config) for c in candidates}) == len(candidates)


def test_the_search_never_reads_the_test_split(run) -> None:
    out, config, _, _, _, splits, first, results = run
    assert splits and set(splits) == {"train"}  # training, snapshot scores and evaluations alike
    for evaluated in (first, results):
        assert evaluated.protocol.split == "train" and evaluated.protocol.scenes == ["Single-Strawberry/000"]
    assert json.loads(results_path(out, config).read_text())["protocol"]["split"] == "train"


def test_every_candidate_is_scored_beside_rand_and_the_best_fixed_action(run) -> None:
    _, config, _, _, _, _, first, results = run
    assert set(first.policies) == {"Rand", "Best fixed action"}
    rows = {c.row(config) for c in TINY}
    assert set(results.policies) == rows | {"Rand", "Best fixed action"}
    assert results.policies["Rand"].exact is not None and results.fixed_actions


def test_a_presets_environments_are_honoured_and_recorded(run) -> None:
    from davis_ag.benchmark.training_record import training_record_path

    out, config, *_ = run
    zoo = json.loads(training_record_path(candidate_model(out, config, TINY[2])).read_text())
    ours = json.loads(training_record_path(candidate_model(out, config, TINY[0])).read_text())
    assert zoo["n_envs"] == 16 and zoo["a2c_settings"]["policy_kwargs"]["optimizer_class"] == "RMSpropTFLike"
    assert ours["n_envs"] == config.n_envs == 2 and "n_envs" not in ours["a2c_settings"]


def test_a_finished_candidate_and_its_evaluation_are_reused(run) -> None:
    out, config, state, record, clock, *_ = run
    models = [candidate_model(out, config, c) for c in TINY]
    before = [os.stat(m).st_mtime_ns for m in models] + [os.stat(results_path(out, config)).st_mtime_ns]
    stages = dict(state.stages)
    for candidate in TINY:
        train_candidate(config, out, candidate, clock, record, **TRAIN)
    evaluate_on_train(config, out, TINY, record)
    after = [os.stat(m).st_mtime_ns for m in models] + [os.stat(results_path(out, config)).st_mtime_ns]
    assert after == before and state.stages == stages


def test_the_page_sets_every_candidate_beside_the_trivial_policies_between_its_markers(run, tmp_path: Path) -> None:
    out, config, state, *_ = run
    page = tmp_path / "a2c-search.md"
    page.write_text("# A2C\n\nprose\n\n<!-- a2c-search:start -->\nold\n<!-- a2c-search:end -->\n\ntail\n")
    write_search_page(page, config, state, out, TINY)
    text = page.read_text()
    assert "prose" in text and "tail" in text and "\nold\n" not in text
    for candidate in TINY:
        line = next(x for x in text.splitlines() if x.startswith(f"| {candidate.row(config)} |"))
        assert "±" in line and "not trained yet" not in line
    assert "| A2C zoo-atari 48 |" in text and "optimizer RMSpropTFLike (eps 1e-05)" in text
    assert " | 16 | " in next(x for x in text.splitlines() if x.startswith("| A2C zoo-atari 48 |"))
    assert next(x for x in text.splitlines() if x.startswith("| Rand |")).count("exact") == 1
    assert "exact" in next(x for x in text.splitlines() if x.startswith("| Best fixed action |"))
    assert 'Chosen by the rule "highest train-split OER_tau" among the 2 of 2 A2C candidates' in text
    assert "the test split is never read by this run" in text


def test_the_page_draws_each_trained_candidates_curves_against_the_trivial_policies(run, tmp_path: Path) -> None:
    from PIL import Image

    out, config, state, *_ = run
    page = tmp_path / "docs" / "search.md"
    page.parent.mkdir()
    write_search_page(page, config, state, out, TINY[:1])  # before any other candidate finished: its curve alone
    picture = page.parent / "images" / "search-curves.png"
    assert "![learning curves of the candidates](images/search-curves.png)" in page.read_text()
    with Image.open(picture) as drawn:
        assert drawn.size[0] > 300
    untrained = (Candidate("a2c-never", "A2C never", "a2c", "sb3", "not trained"),)
    picture.unlink()
    write_search_page(page, config, state, out, untrained)  # nothing trained: no figure, no link
    assert not picture.exists() and "search-curves.png" not in page.read_text()


def test_a_candidate_that_played_one_action_only_is_named_a_fixed_action(run, tmp_path: Path) -> None:
    """A collapsed learner (the zoo's A2C on the paper's network plays one move from 10K steps) must
    not read as a method: the page says which candidate played one action only, and no other."""
    import shutil

    from davis_ag.benchmark.results_table import only_action

    out, config, state, *_ = run
    copy = shutil.copytree(out, tmp_path / "run", ignore=shutil.ignore_patterns("dataset", "*.zip"))
    path = results_path(copy, config)
    data = json.loads(path.read_text())
    ours, up = TINY[0].row(config), data["protocol"]["actions"].index("up")
    for episode in data["policies"][ours]["episodes"]:  # every step "up", as the file's checks recount it
        episode["actions"] = [up] * len(episode["actions"])
    counts = data["policies"][ours]["action_counts"]
    data["policies"][ours]["action_counts"] = {action: 0 for action in counts} | {"up": sum(counts.values())}
    path.write_text(json.dumps(data))
    page = tmp_path / "a2c-search.md"
    write_search_page(page, config, state, copy, TINY)
    text = page.read_text()
    assert f"{ours} played `up` only on these episodes: a fixed action, not a method" in text
    results = load_results(path)
    for candidate in TINY[1:]:
        named = f"{candidate.row(config)} played `" in text
        assert named == (only_action(results.policies[candidate.row(config)]) is not None)


def test_a_page_without_the_runs_markers_is_refused(tmp_path: Path) -> None:
    page = tmp_path / "results.md"
    page.write_text("# Table 4\n")
    with pytest.raises(UserError, match="has no <!-- a2c-search:start --> section"):
        check_page(page)
    check_page(tmp_path / "new.md")  # a page not there yet is written whole
    from davis_ag import cli

    out = tmp_path / "run"
    assert cli.main(["reproduce", "--config", "a2c-search", "--out", str(out), "--results", str(page)]) == 2
    assert page.read_text() == "# Table 4\n" and not (out / "state.json").exists()


def test_the_status_and_the_rewritten_page_of_a_search_run(run, tmp_path: Path, capsys) -> None:
    from davis_ag import cli
    from davis_ag.workflows.reproduce.status import format_status, run_status

    out, *_ = run
    _, stages = run_status(out)
    by_name = {s.stage: s for s in stages}
    assert by_name["sp-strawberry: train a2c-ours"].done and by_name["sp-strawberry: train a2c-zoo-atari"].done
    assert "sp-strawberry: evaluate on train" in by_name and "sp-strawberry: evaluate" not in by_name
    assert "a2c-search" in format_status(out)
    page = tmp_path / "page.md"
    assert cli.main(["reproduce", "--out", str(out), "--results", str(page), "--rewrite-results"]) == 0
    assert "<!-- a2c-search:start -->" in page.read_text() and "| A2C ours 48 |" in page.read_text()


@pytest.mark.parametrize("name", ["a2c-search", "a2c-search-paper-scale"])
def test_the_plan_in_the_docs_is_the_codes(name: str) -> None:
    from davis_ag.workflows.reproduce.pages.a2c_search import PLAN_MARKER, bench_rates, plan_table

    docs = Path(__file__).parents[3] / "docs"
    page = (docs / f"{name}.md").read_text()
    section = page.split(f"<!-- {PLAN_MARKER}:start -->\n", 1)[1].split(f"\n<!-- {PLAN_MARKER}:end -->", 1)[0]
    assert section == plan_table(bench_rates(docs / "performance.md"), CONFIGS[name]), (
        f"docs/{name}.md's plan is stale: python -c \"from pathlib import Path; from davis_ag.atomic_files "
        "import write_marked_section as w; import davis_ag.workflows.reproduce.pages.a2c_search as s; "
        "from davis_ag.workflows.reproduce.configs import CONFIGS; "
        f"w('docs/{name}.md', s.PLAN_MARKER, s.plan_table(s.bench_rates(Path('docs/performance.md')), "
        f"CONFIGS['{name}']))\""
    )


@pytest.mark.slow
def test_a_whole_search_run_and_a_rerun_that_reuses_everything(
    tmp_path: Path, one_thread: None, capsys: pytest.CaptureFixture[str]
) -> None:
    """``reproduce --config a2c-search`` end to end at the smallest size (two real scenes at 160x90):
    data, validation, every candidate and the page; a second sitting trains and scores nothing."""
    from davis_ag.workflows.reproduce.a2c_search import reproduce_a2c_search
    from davis_ag.workflows.reproduce.clock import CLOCK_FILE, read_clock

    config = replace(
        CONFIGS["a2c-search"], size=(160, 90), sp_scenes=2, sp_timesteps=48, n_envs=2, episodes=8, sessions=1
    )
    out, page = tmp_path / "run", tmp_path / "a2c-search.md"
    assert reproduce_a2c_search(config, out, page, TINY, **TRAIN) == 0
    text = page.read_text()
    assert all(f"| {c.row(config)} |" in text for c in TINY) and "not trained yet" not in text
    clock = read_clock(out / CLOCK_FILE)
    assert {f"sp-strawberry: train {c.key}" for c in TINY} <= set(clock)
    evaluated = os.stat(results_path(out, config)).st_mtime_ns
    capsys.readouterr()
    assert reproduce_a2c_search(config, out, page, TINY, **TRAIN) == 0
    assert read_clock(out / CLOCK_FILE) == clock and os.stat(results_path(out, config)).st_mtime_ns == evaluated
    assert "training" not in capsys.readouterr().out
