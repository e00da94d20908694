"""docs/a2c-search.md's run section, written from the ``a2c-search`` run's train-split evaluation:
each candidate's settings, steps, environments, train-split OER_tau beside PPO's, Rand's and the
Best fixed action's, the hours it trained, and the candidate the rule chooses; and the plan
section (each candidate's hours at docs/performance.md's training rates), written before any run.

The page's prose is written by hand; everything between its markers comes from here. A page
without the run's markers (a run's own ``results.md``) is written whole: a title and the section.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from davis_ag.atomic_files import read_page, write_marked_section, write_text_atomic
from davis_ag.benchmark.results import EvaluationResults, load_results, signed_number, table_number
from davis_ag.errors import UserError
from davis_ag.workflows.reproduce.a2c_candidates import (
    MARKER,
    SPLIT,
    Candidate,
    candidates_of,
    group_of,
    results_path,
)
from davis_ag.workflows.reproduce.configs import CONFIGS, ReproduceConfig
from davis_ag.workflows.reproduce.state import RunState

#: The marker of the plan section (:func:`plan_table`).
PLAN_MARKER = "a2c-search-plan"
#: The rows of docs/performance.md's training table each algorithm is timed at.
BENCH_ROWS = {"a2c": "A2C (ours)", "ppo": "PPO (the zoo's Atari settings, ours)"}


def settings_text(settings: dict[str, Any]) -> str:
    """``ent_coef 0.01, vf_coef 0.25, optimizer RMSpropTFLike (eps 1e-05)``: a setting set in words,
    its environments left to their own column."""
    parts = []
    for key, value in settings.items():
        if key == "n_envs":
            continue
        if key == "policy_kwargs":
            extra = ", ".join(f"{k} {v}" for k, v in value.get("optimizer_kwargs", {}).items())
            parts.append(f"optimizer {value.get('optimizer_class', 'RMSprop')}" + (f" ({extra})" if extra else ""))
        else:
            parts.append(f"{key} {str(value).lower() if isinstance(value, bool) else value}")
    return ", ".join(parts) or "SB3's defaults"


def environments(candidate: Candidate, config: ReproduceConfig) -> int:
    """The environments a candidate trains with: its set's own, else the run's."""
    return int((candidate.settings() or {}).get("n_envs", config.n_envs))


def _gap(results: EvaluationResults, name: str, other: str) -> str:
    """``+.030 [+.020, +.039]``: ``name`` minus ``other`` on the same train-split episodes."""
    from davis_ag.benchmark.paired import paired_gap

    first, second = results.policies.get(name), results.policies.get(other)
    if first is None or second is None or first.episodes is None or second.episodes is None or name == other:
        return "-"
    gap = paired_gap(
        [e.model_dump() for e in first.episodes], [e.model_dump() for e in second.episodes], results.protocol.seed
    )
    return f"{signed_number(gap.gap)} [{signed_number(gap.low)}, {signed_number(gap.high)}]"


def _hours(state: RunState, key: str, candidate: Candidate) -> str:
    """The hours a candidate trained, summed over its sittings on the run's clock."""
    record = state.stages.get(f"{key}: train {candidate.key}")
    return f"{record.seconds / 3600:.2f}" if record else "-"


def search_section(
    config: ReproduceConfig,
    state: RunState,
    out: Path,
    candidates: tuple[Candidate, ...] | None = None,
    page: Path | None = None,
) -> str:
    """The run's section: one line per candidate, then Rand and the Best fixed action, then the choice.

    Args:
        config: The run.
        state: Its records (training hours).
        out: The run folder (its train-split evaluation).
        candidates: The search's candidates (None: :func:`candidates_of` the run's).
        page: The page's path, to draw the candidates' curves beside it (:func:`curves_lines`);
            None: no figure.

    Returns:
        Markdown.
    """
    from davis_ag.benchmark.exact import BEST_FIXED
    from davis_ag.benchmark.results_table import only_action

    candidates = candidates or candidates_of(config)
    _, _, key = group_of(config)
    try:
        results: EvaluationResults | None = load_results(results_path(out, config))
    except UserError:
        results = None
    p = results.protocol if results else None
    scenes = f"{len(p.scenes)} train scene(s), {p.starts or 0:,} eligible starts" if p else "not yet evaluated"
    target = next((c.row(config) for c in candidates if c.algo != "a2c"), None)
    played = {r.play for r in (results.policies.values() if results else ()) if r.play}
    play = f" The models play {', '.join(sorted(played))} actions." if played else ""
    lines = [
        f"Written by `davis-ag reproduce --config {config.name}`: {config.scenes_in_words()} at "
        f"{config.size[0]}x{config.size[1]} (dataset seed {config.seed}; {scenes}, split rule "
        f"`{config.split_rule}`). Each candidate trained on the {SPLIT} split only (seed {config.seed}, the "
        "paper's network, the snapshot best on train kept), then scored with Rand and the Best fixed action "
        f"on fresh {SPLIT}-split episodes ({config.sessions} x {config.episodes}, seed {config.seed}); the "
        "test split is never read by this run. OER_tau: mean ± std over sessions (Table 4's ±); gaps: paired on the same "
        "episodes, 95 % bootstrap interval. Rand and the Best fixed action: exact expectations over the "
        f"split's starts (sampled on the same episodes in brackets).{play}",
        "",
        f"| candidate | settings over SB3's defaults | steps | environments | {SPLIT} OER_tau ± std "
        f"| against {target or 'PPO'} | against {BEST_FIXED} | hours on this machine |",
        "|---|---|---|---|---|---|---|---|",
    ]
    scored = results.policies if results else {}
    for c in candidates:
        row = c.row(config)
        result = scored.get(row)
        score = (
            f"{table_number(result.oer_tau.mean)} ± {table_number(result.oer_tau.std)}" if result else "not trained yet"
        )
        against = _gap(results, row, target) if results and target else "-"
        best = _gap(results, row, BEST_FIXED) if results else "-"
        lines.append(
            f"| {row} | {settings_text(c.shown_settings())} | {c.timesteps(config):,} | {environments(c, config)} "
            f"| {score} | {against} | {best} | {_hours(state, key, c)} |"
        )
    for name in ("Rand", BEST_FIXED):
        result = scored.get(name)
        exact = _exact(results, name)
        shown = (
            f"{table_number(exact)} exact ({table_number(result.oer_tau.mean)} sampled)"
            if result and exact is not None
            else "-"
        )
        what = (
            f"always `{result.action}`"
            if result and result.action
            else (
                "always the split's best single action"
                if name == BEST_FIXED
                else "uniform over every action, done included"
            )
        )
        lines.append(f"| {name} | {what} | - | - | {shown} | - | - | - |")
    for c in candidates:
        if (result := scored.get(c.row(config))) and (action := only_action(result)):
            lines += [
                "",
                f"{c.row(config)} played `{action}` only on these episodes: a fixed action, not a method "
                f"({BEST_FIXED}'s row is what always playing the best one scores).",
            ]
    lines += ["", choice_line(config, candidates, results)]
    if page is not None:
        lines += curves_lines(config, out, page, candidates, results)
    lines += ["", "Where each candidate's settings come from:", ""]
    lines += [f"- {c.row(config)}: {c.source}." for c in candidates]
    return "\n".join(lines) + "\n"


def _exact(results: EvaluationResults | None, name: str) -> float | None:
    """Rand's or the Best fixed action's exact expectation over the split's starts, where scored."""
    from davis_ag.benchmark.exact import BEST_FIXED

    result = results.policies.get(name) if results else None
    if result is None:
        return None
    if name == BEST_FIXED and results and results.fixed_actions and result.action:
        return float(results.fixed_actions[result.action]["oer_tau"])
    return (result.exact or {}).get("oer_tau")


def curves_lines(
    config: ReproduceConfig,
    out: Path,
    page: Path,
    candidates: tuple[Candidate, ...],
    results: EvaluationResults | None,
) -> list[str]:
    """Every trained candidate's learning curve and train-split snapshots, drawn into
    ``images/<page>-curves.png`` beside the page, against Rand's and the Best fixed action's
    exact train-split scores, so a candidate that never left their level reads as one that did
    not learn; no lines before a candidate has finished.

    Args:
        config: The run.
        out: The run folder (each candidate's training record beside its model).
        page: The page the figure goes beside.
        candidates: The search's candidates.
        results: The train-split evaluation (the references), None before it.

    Returns:
        Markdown lines.
    """
    from davis_ag.benchmark.exact import BEST_FIXED
    from davis_ag.figures.training_curve import plot_learning_curve
    from davis_ag.workflows.reproduce.learners import training_record

    _, _, key = group_of(config)
    records = {c.row(config): r for c in candidates if (r := training_record(out, key, c.key))}
    references = {}
    for name in ("Rand", BEST_FIXED):
        if results is not None and (value := _exact(results, name)) is not None:
            action = results.policies[name].action
            references[f"{name} (always {action}), exact" if action else f"{name}, exact"] = value
    target = page.parent / "images" / f"{page.stem}-curves"
    try:
        plot_learning_curve(records, target, formats=("png",), references=references)
    except UserError:  # none finished yet, or records from before curves were kept
        return []
    return [
        "",
        "Each trained candidate's mean episodic reward per 1,000 training steps (top) and the "
        f"{SPLIT}-split OER_tau of its snapshots (below; ringed: the one kept), against Rand's and the "
        f"Best fixed action's exact {SPLIT}-split scores (dashed, dotted):",
        "",
        f"![learning curves of the candidates](images/{target.name}.png)",
    ]


def choice_line(config: ReproduceConfig, candidates: tuple[Candidate, ...], results: EvaluationResults | None) -> str:
    """The rule's choice: the A2C candidate with the highest train-split OER_tau, beside the target."""
    scored = results.policies if results else {}
    a2c = [c.row(config) for c in candidates if c.algo == "a2c" and c.row(config) in scored]
    if not a2c:
        return "No A2C candidate trained yet: the rule (highest train-split OER_tau) has nothing to choose from."
    best = max(a2c, key=lambda row: scored[row].oer_tau.mean)
    total = sum(c.algo == "a2c" for c in candidates)
    line = (
        f'Chosen by the rule "highest {SPLIT}-split OER_tau" among the {len(a2c)} of {total} A2C candidates '
        f"trained: **{best}** ({table_number(scored[best].oer_tau.mean)})"
    )
    target = next((c.row(config) for c in candidates if c.algo != "a2c"), None)
    if target and target in scored:
        gap = scored[best].oer_tau.mean - scored[target].oer_tau.mean
        line += f", {signed_number(gap)} beside {target}'s {table_number(scored[target].oer_tau.mean)}"
    elif target:
        line += f"; {target} not trained yet"
    return line + "."


def write_search_page(
    path: Path, config: ReproduceConfig, state: RunState, out: Path, candidates: tuple[Candidate, ...] | None = None
) -> None:
    """Write the run's section into ``path`` (between its markers), or the whole page when it has none.

    Args:
        path: The page.
        config: The run.
        state: Its records.
        out: The run folder.
        candidates: The search's candidates (None: :func:`candidates_of` the run's).
    """
    text = search_section(config, state, out, candidates, Path(path))
    start = f"<!-- {MARKER}:start -->"
    if path.is_file() and start in read_page(path, "--results"):
        write_marked_section(path, MARKER, text)
    else:
        write_text_atomic(
            path, f"# A2C settings searched on the train split\n\n{start}\n{text}\n<!-- {MARKER}:end -->\n"
        )


def bench_rates(performance_md: Path) -> dict[str, float]:
    """Steps per second of A2C (ours) and PPO (the zoo's) in docs/performance.md's training table
    (``make bench`` writes it), by algorithm.

    Raises:
        UserError: when the page has no such table.
    """
    text = read_page(performance_md, "docs/performance.md")
    section = text.split("<!-- bench-training:start -->", 1)[-1].split("<!-- bench-training:end -->", 1)[0]
    rates = {}
    for algo, row in BENCH_ROWS.items():
        found = re.search(rf"^\| {re.escape(row)} \| \*\*([0-9.]+)\*\* \|", section, re.MULTILINE)
        if found is None:
            raise UserError(f"{performance_md}: no `{row}` row in its bench-training table: run `make bench`")
        rates[algo] = float(found.group(1))
    return rates


def plan_table(rates: dict[str, float], config: ReproduceConfig | None = None) -> str:
    """The search's plan: each candidate's settings, steps and environments, and its training hours
    at the training table's rates (one step of A2C costs about the same with 16 environments as
    with 8: the same passes per observation).

    Args:
        rates: Steps per second by algorithm (:func:`bench_rates`).
        config: The search (default: ``a2c-search``); its candidates are :func:`candidates_of`'s.

    Returns:
        A Markdown table and a line with the total.
    """
    config = config or CONFIGS["a2c-search"]
    candidates = candidates_of(config)
    lines = [
        "| candidate | settings over SB3's defaults | steps | environments | hours at performance.md's rate |",
        "|---|---|---|---|---|",
    ]
    total = 0.0
    for c in candidates:
        hours = c.timesteps(config) / rates[c.algo] / 3600
        total += hours
        lines.append(
            f"| {c.row(config)} | {settings_text(c.shown_settings())} | {c.timesteps(config):,} "
            f"| {environments(c, config)} | {hours:.1f} |"
        )
    lines += [
        "",
        f"About {total:.1f} hours of training at those rates ({BENCH_ROWS['a2c']} "
        f"{rates['a2c']} steps/s, {BENCH_ROWS['ppo']} {rates['ppo']}), {sum(c.timesteps(config) for c in candidates):,} "
        "steps in all, before the scenes, their validation and the snapshot scores.",
    ]
    return "\n".join(lines)
