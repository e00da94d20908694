"""``docs/results.md`` of a ``davis-ag reproduce`` run, written wholly from the run's own records.

What it reads: the run's ``state.json`` (configuration, stage times, each evaluation without its
episodes: :class:`~davis_ag.workflows.reproduce.state.RunState`), each
scene's ``scene.json`` (the code version, renderer and image size that made it), each model's
``NAME.training.json`` (the sittings a training run took, with their code versions) and this
machine. Nothing in the file is typed by hand, so a re-run rewrites all of it, and a run resumed
across code changes says so itself.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from davis_ag.benchmark.results import PolicyResult
from davis_ag.provenance import machine_description
from davis_ag.scene.specs import PAPER_TABLE3
from davis_ag.workflows.reproduce.configs import ReproduceConfig
from davis_ag.workflows.reproduce.groups import GROUPS
from davis_ag.workflows.reproduce.learners import LEARNERS, training_record
from davis_ag.workflows.reproduce.pages.paper_table4 import (
    PAPER_ORDERINGS,
    PAPER_TABLE4,
    PAPER_TABLE4_STD,
    PAPER_TIMESTEPS,
    TITLES,
    cell,
    ordering_failures,
    ordering_holds,
    paper_cells,
)
from davis_ag.workflows.reproduce.pages.policies import (
    learners_run,
    learning_curve_section,
    ordered,
    policy_sections,
)
from davis_ag.workflows.reproduce.pages.provenance import how_made, stage_rows
from davis_ag.workflows.reproduce.pages.split_rules import RuleRun, split_rules_section
from davis_ag.workflows.reproduce.state import RunState


def _a2c_play(state: RunState) -> str:
    """How the run's A2C played: ``sampled``, ``deterministic`` (the default before it was recorded)."""
    plays = {r.policies["A2C"].play or "deterministic" for r in state.results.values() if "A2C" in r.policies}
    if not plays:
        return "not evaluated yet"
    return (
        "sampled"
        if plays == {"sampled"}
        else "deterministic"
        if plays <= {"deterministic"}
        else "sampled and deterministic"
    )


def _notes(config: ReproduceConfig, state: RunState, out: Path | None) -> list[str]:
    """Plain statements of where this run differs from the paper's, from what it measured."""
    notes = []
    for scenario, key in GROUPS.items():
        for learner in LEARNERS:
            record = training_record(out, key, learner)
            steps, rate = record.get("timesteps"), record.get("steps_per_second")
            if steps and rate and steps < PAPER_TIMESTEPS:
                notes.append(
                    f"{learner} on {key} trained for {steps:,} environment steps, {steps / PAPER_TIMESTEPS:.1%} "
                    f"of the paper's 300K, at {rate:.1f} steps/s on this machine: the {learner} row is an "
                    "under-trained agent" + (", not the paper's." if learner == "A2C" else ".")
                )
        result = state.results.get(scenario)
        if result is not None:
            protocol = result.protocol
            scenes = protocol.scenes
            if protocol.split == "all":
                notes.append(
                    f"{key}: only {len(scenes)} scene(s), so no test scene exists; the "
                    "benchmark ran on split `all`, i.e. on the scene(s) A2C trained on "
                    "(in-sample for A2C; the heuristics and the Oracle do not learn)."
                )
            else:
                rule = protocol.split_rule or "scenes"
                how = (
                    "70/30 split by scene, seeded"
                    if rule == "scenes"
                    else f"split rule `{rule}`: 70/30 of each group's {rule}, seeded, train and test on the same scenes"
                )
                notes.append(
                    f"{key}: evaluated on the test split, {len(scenes)} scene(s): {', '.join(scenes)} ({how})."
                )
    for scenario, result in state.results.items():
        lengths = {n: p.length.mean for n, p in result.policies.items()}
        if lengths.get("LRD") is not None and lengths.get("LRD") == lengths.get("UDD"):
            notes.append(
                f"{scenario.upper()}: LRD and UDD have the same episode lengths because every "
                "policy plays the same seeded episodes with the same agent seeds, and both "
                "draw `done` with probability 1/3 at each step (common random numbers)."
            )
    notes.append(
        "Stage times are wall times summed over every sitting that worked on the stage (the run's "
        "clock, written each minute, so a sitting ended by a kill counts, with the work it redoes); "
        "scenes made before a run had the clock count their own times over the scene processes "
        "that ran at once. Other work may share the machine, so rates (e.g. A2C steps/s) can vary "
        "between stages."
    )
    notes.append(
        "Oracle is not in the paper: it plays the best reachable final OER within tau "
        "steps from the environment's tables, an upper bound for any policy."
    )
    for scenario, result in state.results.items():
        protocol = result.protocol
        rule = protocol.start_rule or "scene"
        how = (
            "uniform over every eligible (view, target) pair of the split's scenes"
            if rule == "pairs"
            else "a scene first, then a view of it, then a target, each uniformly (the rule before; a scene "
            "with few eligible starts gets as many episodes as one with many)"
        )
        count = f" ({protocol.starts} eligible starts)" if protocol.starts is not None else ""
        notes.append(
            f"{scenario.upper()} episode starts{count}: {how}. Eligible (section V-D): a boxed target "
            "with OER < 0.4 and at least the crop's pixel threshold; reward max(OER_end - OER_0, 0)^2 "
            "at the end."
        )
    return notes


def _comparison(scenario: str, policies: Mapping[str, PolicyResult]) -> str:
    order = PAPER_ORDERINGS[scenario]
    failures = ordering_failures(order, {name: policy.oer_tau for name, policy in policies.items()})
    text = " ".join(order)
    if failures is None:
        return f"The paper's ordering of OER_tau, {text}, cannot be checked: a policy was not run."
    measured = ", ".join(
        f"{name} {cell(policies[name].oer_tau.mean)} ± {cell(policies[name].oer_tau.std)}" for name in order[::2]
    )
    verdict = "holds" if not failures else "does not hold"
    paper_note = "" if ordering_holds(order, paper_cells(scenario)) else " (nor does it hold in Table 4's own numbers)"
    where = "" if not failures else " " + "; ".join(failures) + "."
    return (
        f"The paper's ordering of OER_tau, {text} (`>`: higher mean; `~`: means within the two standard "
        f"deviations added), **{verdict}** in this run{paper_note}: {measured}.{where}"
    )


#: The page's first line; a run under a rule other than ``scenes`` names it after a comma.
PAGE_TITLE = "# Table 4 reproduction"


def page_title(rule: str) -> str:
    """The first line of a Table 4 page of a run under ``rule``."""
    return PAGE_TITLE if rule == "scenes" else f"{PAGE_TITLE}, split rule `{rule}`"


def page_split_rule(text: str) -> str | None:
    """The split rule of a Table 4 page's run, read from its title; ``None`` for another page."""
    first = text.split("\n", 1)[0].strip()
    if first == PAGE_TITLE:
        return "scenes"
    prefix = f"{PAGE_TITLE}, split rule `"
    if first.startswith(prefix) and first.endswith("`"):
        return first[len(prefix) : -1]
    return None


def write_results_md(
    path: Path,
    config: ReproduceConfig,
    state: RunState,
    out: Path | None = None,
    beside: Sequence[RuleRun] = (),
) -> Path:
    """Write the Markdown results: our Table 4 beside the paper's, how the run was made, the timings.

    Args:
        path: The Markdown file.
        config: The run's :class:`~davis_ag.workflows.reproduce.configs.ReproduceConfig`.
        state: The run's records: ``results`` (per scenario), ``stages`` (seconds, notes,
            code) and ``scene_folders`` (per group).
        out: The work folder, for the scene and training records.
        beside: Runs of the same configuration under other split rules: the page gains the
            section on both readings of the split (:mod:`~davis_ag.workflows.reproduce.pages.split_rules`).

    Returns:
        ``path``.
    """
    from davis_ag.atomic_files import write_text_atomic
    from davis_ag.scene.specs import crop_spec, scenario_spec
    from davis_ag.scene.view_grid import views_per_scene
    from davis_ag.workflows.reproduce.clock import CLOCK_FILE, machines, read_clock
    from davis_ag.workflows.reproduce.pages.blocks import write_blocks_beside

    strawberry, vine = crop_spec("strawberry"), crop_spec("vine")
    sp_views = views_per_scene(scenario_spec("sp", strawberry), strawberry)
    sp_extent = " x ".join(f"{side:g}" for side in strawberry.sp_extent)
    mp_views = views_per_scene(scenario_spec("mp", vine), vine)
    mp_grid = (
        f"{config.mp_extent[0]:g} x {config.mp_extent[1]:g} m around the middle vine"
        if config.mp_extent
        else f"section III-B's 7 x 3 m, {mp_views} views each"
    )
    lines = [
        page_title(config.split_rule),
        "",
        "Written by `davis-ag reproduce` from the run's own records; do not edit by hand. Every number in "
        "the *ours* columns was measured by the run described here; the *paper* columns are Table 4 of "
        "the paper.",
        "",
        f"- **Configuration** `{config.name}`: {config.sp_scenes} SP strawberry scene(s) (strawberry's "
        f"{sp_extent} m grid, {sp_views} views each, as Table 3 counts them) and {config.mp_scenes} MP vine scene(s) (grid {mp_grid}, 0.5 m "
        f"step, 12 headings, 2 altitudes) at {config.size[0]}x{config.size[1]}, dataset seed "
        f"{config.seed}; box thresholds scaled by image area; A2C (Stable-Baselines3, the paper's "
        f"network of section V-C, {config.n_envs} environments; its settings under each scenario) for {config.sp_timesteps:,} (SP) and "
        f"{config.mp_timesteps:,} (MP) environment steps"
        + (
            "; PPO beside it (RL Baselines3 Zoo's Atari settings, the same network, steps, seed, train split and keep-best-train rule)"
            if "PPO" in learners_run(state, out)
            else ""
        )
        + f"; evaluation {config.sessions} sessions x "
        f"{config.episodes} episodes, seed {config.seed}, A2C {_a2c_play(state)}.",
        f"- **Paper**: {PAPER_TABLE3['sp', 'strawberry'][0]} SP strawberry and {PAPER_TABLE3['mp', 'vine'][0]} "
        "MP vine scenes at 1280x720 "
        "(Table 3), A2C for 300K "
        "steps, 3 sessions x 200 episodes on the test split.",
        f"- **Machine**: {machine_description()}.",
        "",
    ]
    for scenario in ("sp", "mp"):
        lines += [f"## {TITLES[scenario]}", ""]
        result = state.results.get(scenario)
        if result is None:
            lines += ["Not evaluated yet: the run had not reached this benchmark when this page was written.", ""]
            continue
        protocol, policies = result.protocol, result.policies
        starts = f", {protocol.starts:,} eligible starts" if protocol.starts is not None else ""
        if result.train_split is not None:
            starts += f"; the train split: {result.train_split.starts:,} eligible starts"
        lines += [
            f"Split `{protocol.split}` ({len(protocol.scenes)} scene(s){starts}), "
            f"tau = {protocol.tau}; ours: mean ± std over {protocol.sessions} "
            f"sessions of {protocol.episodes} episodes.",
            "",
            "| Policy | OER_tau ours | OER_tau paper | Cum. reward ours | Cum. reward paper "
            "| Ep. length ours | Ep. length paper |",
            "|---|---|---|---|---|---|---|",
        ]
        for name in ordered(policies):
            cells = [name]
            row = policies[name]
            for metric, stat in (("oer_tau", row.oer_tau), ("reward", row.reward), ("length", row.length)):
                cells.append(f"{cell(stat.mean)} ± {cell(stat.std)}")
                paper_mean = PAPER_TABLE4[scenario][metric].get(name)
                cells.append(
                    cell(paper_mean)
                    if paper_mean is None
                    else f"{cell(paper_mean)} ± {cell(PAPER_TABLE4_STD[scenario][metric][name])}"
                )
            lines.append("| " + " | ".join(cells) + " |")
        lines += ["", _comparison(scenario, policies)]
        if "LRD" in policies:
            text = f"Mean start OER (OER_0) of these episodes: {cell(policies['LRD'].oer_0.mean)}"
            done = (result.fixed_actions or {}).get("done")
            if done:
                # Always `done` ends where it starts: its exact OER_tau is the mean OER_0 of all starts.
                text += (
                    f", against {cell(done['oer_tau'])} over every eligible start of the split (exact). "
                    "Every policy plays the same drawn starts, so the draw moves all their sampled "
                    "means together; the exact values below do not depend on it"
                )
            lines += ["", text + "."]
        lines.append("")
        lines += policy_sections(scenario, result, out, Path(path))
    lines += learning_curve_section(out, Path(path), state.results)
    if beside:
        lines += split_rules_section([RuleRun(config, state, out), *beside])
    lines += ["## Notes", ""] + [f"- {note}" for note in _notes(config, state, out)] + [""]
    lines += how_made(state, out)
    lines += [
        "## Wall time per stage",
        "",
        "| Stage | Seconds | Hours | Ran on (the clock's sittings) | Code | Note |",
        "|---|---|---|---|---|---|",
    ]
    clock = read_clock(out / CLOCK_FILE) if out is not None else {}
    stages = []  # (stage, seconds, sittings), for the blocks beside the page
    for stage, seconds, code, note in stage_rows(state, out):
        stages.append((stage, seconds, clock.get(stage, [])))
        where = machines(clock.get(stage, []))
        lines.append(f"| {stage} | {seconds:.0f} | {seconds / 3600:.2f} | {where} | {code} | {note} |")
    total = sum(seconds for _, seconds, _ in stages)
    lines += [f"| total | {total:.0f} | {total / 3600:.2f} | | | |", ""]
    written = write_text_atomic(path, "\n".join(lines) + "\n")
    # A page in a project's docs/ also rewrites its blocks in the README and docs/benchmark.md,
    # so their numbers are the run's, never copied by hand.
    write_blocks_beside(Path(path), config, state, out, stages, beside)
    return written
