"""``docs/results.md`` of a ``davis-ag reproduce`` run, written wholly from the run's own records.

What it reads: the run's ``state.json`` (configuration, stage times, evaluation summaries), each
scene's ``scene.json`` (the code version, renderer and image size that made it), each model's
``NAME.training.json`` (the sittings a training run took, with their code versions) and this
machine. Nothing in the file is typed by hand, so a re-run rewrites all of it, and a run resumed
across code changes says so itself.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from davis_ag.benchmark.exact import BEST_FIXED
from davis_ag.benchmark.paired import CONFIDENCE, paired_key
from davis_ag.provenance import machine_description
from davis_ag.scene.specs import PAPER_TABLE3
from davis_ag.workflows.results_policies import (
    LEARNERS,
    cell,
    learning_curve_section,
    ordered,
    policy_sections,
    signed,
    training_record,
)
from davis_ag.workflows.run_groups import GROUPS
from davis_ag.workflows.results_provenance import how_made, stage_rows

#: Table 4 of the paper: scenario -> metric -> policy -> value.
PAPER_TABLE4: dict[str, dict[str, dict[str, float]]] = {
    "sp": {
        "oer_tau": {"A2C": 0.520, "LRD": 0.433, "UDD": 0.371, "Rand": 0.438},
        "reward": {"A2C": 0.052, "LRD": 0.026, "UDD": 0.008, "Rand": 0.027},
        "length": {"A2C": 2.987, "LRD": 2.157, "UDD": 2.137, "Rand": 2.652},
    },
    "mp": {
        "oer_tau": {"A2C": 0.369, "LRD": 0.316, "UDD": 0.313, "Rand": 0.340},
        "reward": {"A2C": 0.020, "LRD": 0.006, "UDD": 0.004, "Rand": 0.012},
        "length": {"A2C": 5.000, "LRD": 2.558, "UDD": 2.683, "Rand": 4.163},
    },
}
#: Table 4's standard deviations (over its three sets of 200 episodes), in the same layout.
PAPER_TABLE4_STD: dict[str, dict[str, dict[str, float]]] = {
    "sp": {
        "oer_tau": {"A2C": 0.004, "LRD": 0.007, "UDD": 0.008, "Rand": 0.101},
        "reward": {"A2C": 0.001, "LRD": 0.002, "UDD": 0.002, "Rand": 0.002},
        "length": {"A2C": 0.008, "LRD": 0.043, "UDD": 0.036, "Rand": 0.056},
    },
    "mp": {
        "oer_tau": {"A2C": 0.009, "LRD": 0.008, "UDD": 0.006, "Rand": 0.002},
        "reward": {"A2C": 0.003, "LRD": 0.002, "UDD": 0.001, "Rand": 0.002},
        "length": {"A2C": 0.000, "LRD": 0.097, "UDD": 0.118, "Rand": 0.058},
    },
}
#: The orderings of OER_tau that section VI reads from Table 4: each step is ``>`` (better) or
#: ``~`` (about equal), left to right.
PAPER_ORDERINGS: dict[str, tuple[str, ...]] = {
    "sp": ("A2C", ">", "Rand", "~", "LRD", ">", "UDD"),
    "mp": ("A2C", ">", "Rand", ">", "LRD", "~", "UDD"),
}
#: The 300K environment steps of A2C training in section VI.
PAPER_TIMESTEPS = 300_000
TITLES = {"sp": "SP strawberry", "mp": "MP vine"}


def ordering_failures(
    order: tuple[str, ...], policies: dict[str, dict[str, Any]], metric: str = "oer_tau"
) -> list[str] | None:
    """The steps of an ordering such as ``A2C > Rand ~ LRD > UDD`` that measured means and stds break.

    ``a > b`` holds when a's mean exceeds b's; ``a ~ b`` when the means differ by no more than the
    two standard deviations (over sessions) added.

    Returns:
        One sentence per broken step (empty when the ordering holds); None when a policy in the
        ordering was not measured.
    """
    try:
        stats = {name: policies[name][metric] for name in order[::2]}
    except KeyError:
        return None
    failures = []
    for left, relation, right in zip(order[0::2], order[1::2], order[2::2]):
        a, b = stats[left], stats[right]
        if relation == ">" and not a["mean"] > b["mean"]:
            failures.append(f"{left} > {right} fails: {cell(a['mean'])} is not above {cell(b['mean'])}")
        gap, spread = abs(a["mean"] - b["mean"]), a["std"] + b["std"]
        if relation == "~" and gap > spread:
            failures.append(
                f"{left} ~ {right} fails: {cell(a['mean'])} and {cell(b['mean'])} are "
                f"{cell(gap)} apart, more than their stds added ({cell(spread)})"
            )
    return failures


def ordering_holds(order: tuple[str, ...], policies: dict[str, dict[str, Any]], metric: str = "oer_tau") -> bool | None:
    """Whether an ordering holds for measured means and stds (:func:`ordering_failures`).

    Returns:
        True or False; None when a policy in the ordering was not measured.
    """
    failures = ordering_failures(order, policies, metric)
    return None if failures is None else not failures


def _a2c_play(state: dict[str, Any]) -> str:
    """How the run's A2C played: ``sampled``, ``deterministic`` (the default before it was recorded)."""
    plays = {
        r["policies"]["A2C"].get("play", "deterministic")
        for r in state.get("results", {}).values()
        if "A2C" in r.get("policies", {})
    }
    if not plays:
        return "not evaluated yet"
    return (
        "sampled"
        if plays == {"sampled"}
        else "deterministic"
        if plays <= {"deterministic"}
        else "sampled and deterministic"
    )


def learners_run(state: dict[str, Any], out: Path | None = None) -> list[str]:
    """The learners (:data:`LEARNERS`) this run evaluated or trained, from its records only (a run
    from before PPO names A2C alone, whatever the configuration now lists)."""
    rows = {name for result in state.get("results", {}).values() for name in result.get("policies", {})}
    return [
        learner
        for learner in LEARNERS
        if learner in rows or any(training_record(out, key, learner) for key in GROUPS.values())
    ]


def _notes(config: Any, state: dict[str, Any], out: Path | None) -> list[str]:
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
        result = state.get("results", {}).get(scenario)
        if result:
            protocol = result["protocol"]
            scenes = protocol.get("scenes", [])
            if protocol["split"] == "all":
                notes.append(
                    f"{key}: only {len(scenes)} scene(s), so no test scene exists; the "
                    "benchmark ran on split `all`, i.e. on the scene(s) A2C trained on "
                    "(in-sample for A2C; the heuristics and the Oracle do not learn)."
                )
            else:
                notes.append(
                    f"{key}: evaluated on the test split, {len(scenes)} scene(s): "
                    f"{', '.join(scenes)} (70/30 split by scene, seeded)."
                )
    for scenario, result in state.get("results", {}).items():
        lengths = {n: p.get("length", {}).get("mean") for n, p in result["policies"].items()}
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
    for scenario, result in state.get("results", {}).items():
        protocol = result["protocol"]
        rule = protocol.get("start_rule", "scene")
        how = (
            "uniform over every eligible (view, target) pair of the split's scenes"
            if rule == "pairs"
            else "a scene first, then a view of it, then a target, each uniformly (the rule before; a scene "
            "with few eligible starts gets as many episodes as one with many)"
        )
        count = f" ({protocol['starts']} eligible starts)" if "starts" in protocol else ""
        notes.append(
            f"{scenario.upper()} episode starts{count}: {how}. Eligible (section V-C): a boxed target "
            "with OER < 0.4 and at least the crop's pixel threshold; reward max(OER_end - OER_0, 0)^2 "
            "at the end."
        )
    return notes


def _comparison(scenario: str, policies: dict[str, dict[str, Any]]) -> str:
    order = PAPER_ORDERINGS[scenario]
    paper = {
        name: {"oer_tau": {"mean": value, "std": PAPER_TABLE4_STD[scenario]["oer_tau"][name]}}
        for name, value in PAPER_TABLE4[scenario]["oer_tau"].items()
    }
    failures = ordering_failures(order, policies)
    text = " ".join(order)
    if failures is None:
        return f"The paper's ordering of OER_tau, {text}, cannot be checked: a policy was not run."
    measured = ", ".join(
        f"{name} {cell(policies[name]['oer_tau']['mean'])} ± {cell(policies[name]['oer_tau']['std'])}"
        for name in order[::2]
    )
    verdict = "holds" if not failures else "does not hold"
    paper_note = "" if ordering_holds(order, paper) else " (nor does it hold in Table 4's own numbers)"
    where = "" if not failures else " " + "; ".join(failures) + "."
    return (
        f"The paper's ordering of OER_tau, {text} (`>`: higher mean; `~`: means within the two standard "
        f"deviations added), **{verdict}** in this run{paper_note}: {measured}.{where}"
    )


#: The README's block that holds the run's OER_tau beside Table 4's (see :func:`readme_block`).
README_MARKER = "results-table4"


def readme_block(config: Any, state: dict[str, Any]) -> str:
    """The README's short Table 4: OER_tau, ours beside the paper's, and whether the orderings hold.

    Args:
        config: The run's :class:`~davis_ag.workflows.reproduce.ReproduceConfig`.
        state: The run's ``state.json`` (its ``results``).

    Returns:
        Markdown: a line on the run, a table, a line per ordering.
    """
    results = state.get("results", {})
    learners = [n for n in LEARNERS if n == "A2C" or n in learners_run(state)]
    head = (
        f"`{config.name}` run (docs/results.md): {config.sp_scenes} SP strawberry and {config.mp_scenes} "
        f"MP vine scenes at {config.size[0]}x{config.size[1]}, {' and '.join(learners)} "
        f"{config.sp_timesteps:,} (SP) and "
        f"{config.mp_timesteps:,} (MP) steps; OER_tau, mean ± std over {config.sessions} sessions of "
        f"{config.episodes} episodes on the split each row names. Table 4's rows are the paper's."
    )
    extra = [n for n in learners if n != "A2C"]  # learners the paper did not train: ours only
    columns = ["A2C", *extra, "LRD", "UDD", "Rand", "Oracle", BEST_FIXED]
    lines = [
        head,
        "",
        "| | A2C | "
        + "".join(f"{n} (ours only) | " for n in extra)
        + "LRD | UDD | Rand | Oracle (ours only) | Best fixed action (ours only) |",
        "|---" * (len(columns) + 1) + "|",
    ]
    verdicts = []
    for scenario in ("sp", "mp"):
        result = results.get(scenario)
        if result:
            policies = result["policies"]
            scenes, split = len(result["protocol"].get("scenes", [])), result["protocol"]["split"]
            cells = [
                f"{cell(policies[n]['oer_tau']['mean'])} ± {cell(policies[n]['oer_tau']['std'])}"
                if n in policies
                else "–"
                for n in columns
            ]
            lines.append(
                f"| {TITLES[scenario]}, ours ({scenes} {split} scene{'s' if scenes != 1 else ''}) | "
                + " | ".join(cells)
                + " |"
            )
            failures = ordering_failures(PAPER_ORDERINGS[scenario], policies)
            verdict = (
                "not checked"
                if failures is None
                else "**holds**"
                if not failures
                else "**does not hold** (" + "; ".join(failures) + ")"
            )
            verdicts.append(f"{TITLES[scenario]}: {' '.join(PAPER_ORDERINGS[scenario])} {verdict}.")
        else:
            lines.append(f"| {TITLES[scenario]}, ours | not run |" + " |" * (len(columns) - 1))
        paper = PAPER_TABLE4[scenario]["oer_tau"]
        lines.append(
            f"| {TITLES[scenario]}, paper (Table 4) | "
            + " | ".join(
                f"{cell(paper[n])} ± {cell(PAPER_TABLE4_STD[scenario]['oer_tau'][n])}" if n in paper else "-"
                for n in columns[:-2]
            )
            + " | - | - |"
        )
    if verdicts:
        lines += [
            "",
            "The paper's orderings in this run (`~`: means within their two standard deviations "
            "added): " + " ".join(verdicts),
        ]
    for learner in learners:
        gaps = [
            f"{TITLES[s]} {signed(p['gap'])} ({signed(p['low'])} to {signed(p['high'])})"
            for s in ("sp", "mp")
            if (p := results.get(s, {}).get(paired_key(learner)))
        ]
        if gaps:
            lines += [
                "",
                f"{learner} minus `{BEST_FIXED}` on the same episodes ({CONFIDENCE:.0%} bootstrap interval over "
                "the test episodes): " + ", ".join(gaps) + ".",
            ]
    return "\n".join(lines)


def write_results_md(path: Path, config: Any, state: dict[str, Any], out: Path | None = None) -> Path:
    """Write the Markdown results: our Table 4 beside the paper's, how the run was made, the timings.

    Args:
        path: The Markdown file.
        config: The run's :class:`~davis_ag.workflows.reproduce.ReproduceConfig`.
        state: The run's ``state.json``: ``results`` (per scenario), ``stages`` (seconds, notes,
            code) and ``scene_folders`` (per group).
        out: The work folder, for the scene and training records.

    Returns:
        ``path``.
    """
    from davis_ag.atomic_files import write_marked_section, write_text_atomic
    from davis_ag.workflows.stage_clock import CLOCK_FILE, machines, read_clock
    from davis_ag.scene.specs import crop_spec, scenario_spec
    from davis_ag.scene.view_grid import views_per_scene

    strawberry, vine = crop_spec("strawberry"), crop_spec("vine")
    sp_views = views_per_scene(scenario_spec("sp", strawberry), strawberry)
    mp_views = views_per_scene(scenario_spec("mp", vine), vine)
    mp_grid = (
        f"{config.mp_extent[0]:g} x {config.mp_extent[1]:g} m around the middle vine"
        if config.mp_extent
        else f"Table 2's 7 x 3 m, {mp_views} views each"
    )
    lines = [
        "# Table 4 reproduction",
        "",
        "Written by `davis-ag reproduce` from the run's own records; do not edit by hand. Every number in "
        "the *ours* columns was measured by the run described here; the *paper* columns are Table 4 of "
        "the paper.",
        "",
        f"- **Configuration** `{config.name}`: {config.sp_scenes} SP strawberry scene(s) (Table 2's "
        f"grid, {sp_views} views each) and {config.mp_scenes} MP vine scene(s) (grid {mp_grid}, 0.5 m "
        f"step, 12 headings, 2 altitudes) at {config.size[0]}x{config.size[1]}, dataset seed "
        f"{config.seed}; box thresholds scaled by image area; A2C (Stable-Baselines3, the paper's "
        f"network of section V-B, {config.n_envs} environments; its settings under each scenario) for {config.sp_timesteps:,} (SP) and "
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
        result = state.get("results", {}).get(scenario)
        if not result:
            lines += ["Not run (yet): the run stopped before this benchmark.", ""]
            continue
        protocol, policies = result["protocol"], result["policies"]
        starts = f", {protocol['starts']:,} eligible starts" if "starts" in protocol else ""
        if "starts" in result.get("train_split", {}):
            starts += f"; the train split: {result['train_split']['starts']:,} eligible starts"
        lines += [
            f"Split `{protocol['split']}` ({len(protocol.get('scenes', []))} scene(s){starts}), "
            f"tau = {protocol['tau']}; ours: mean ± std over {protocol['sessions']} "
            f"sessions of {protocol['episodes']} episodes.",
            "",
            "| Policy | OER_tau ours | OER_tau paper | Cum. reward ours | Cum. reward paper "
            "| Ep. length ours | Ep. length paper |",
            "|---|---|---|---|---|---|---|",
        ]
        for name in ordered(policies):
            cells = [name]
            for metric in ("oer_tau", "reward", "length"):
                stat = policies[name][metric]
                cells.append(f"{cell(stat['mean'])} ± {cell(stat['std'])}")
                paper_mean = PAPER_TABLE4[scenario][metric].get(name)
                cells.append(
                    cell(paper_mean)
                    if paper_mean is None
                    else f"{cell(paper_mean)} ± {cell(PAPER_TABLE4_STD[scenario][metric][name])}"
                )
            lines.append("| " + " | ".join(cells) + " |")
        lines += ["", _comparison(scenario, policies)]
        if "oer_0" in policies.get("LRD", {}):
            text = f"Mean start OER (OER_0) of these episodes: {cell(policies['LRD']['oer_0']['mean'])}"
            done = result.get("fixed_actions", {}).get("done")
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
    lines += learning_curve_section(out, Path(path), state.get("results", {}))
    lines += ["## Notes", ""] + [f"- {note}" for note in _notes(config, state, out)] + [""]
    lines += how_made(state, out)
    lines += [
        "## Wall time per stage",
        "",
        "| Stage | Seconds | Hours | Ran on (the clock's sittings) | Code | Note |",
        "|---|---|---|---|---|---|",
    ]
    total = 0.0
    clock = read_clock(out / CLOCK_FILE) if out is not None else {}
    for stage, seconds, code, note in stage_rows(state, out):
        total += seconds
        where = machines(clock.get(stage, []))
        lines.append(f"| {stage} | {seconds:.0f} | {seconds / 3600:.2f} | {where} | {code} | {note} |")
    lines += [f"| total | {total:.0f} | {total / 3600:.2f} | | | |", ""]
    written = write_text_atomic(path, "\n".join(lines) + "\n")
    # A page in a project's docs/ also updates the README's block beside it, so the README's
    # numbers are the run's, never copied by hand.
    folder = Path(path).absolute().parent
    readme = folder.parent / "README.md"
    if folder.name == "docs" and readme.is_file() and f"<!-- {README_MARKER}:start -->" in readme.read_text():
        write_marked_section(readme, README_MARKER, readme_block(config, state))
    return written
