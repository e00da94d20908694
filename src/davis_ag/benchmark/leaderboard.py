"""A leaderboard from results files (``davis-ag compare``): one row per method, ranked by OER_tau.

Results are ranked together only when they measure the same thing: the same protocol version,
the same evaluated scenes (each one's identity in :class:`davis_ag.benchmark.results.DatasetIdentity`:
seed, code, how it was drawn; scenes the dataset gained since, another crop's group, change nothing
a file measured), environment, scenario, crop, split and split rule (hence scenes and eligible starts). Anything
else is refused in one line.
Files may differ in sessions, episodes or seed; then their means are still comparable (each an
estimate of the same expectation), but their episodes are not the same, and a paired gap is
given only between policies that played the same episodes: within one file, or across files of
the same seed, sessions and episodes that kept their episodes.
"""

from __future__ import annotations

import os
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from davis_ag.benchmark.paired import FEW_SCENES
from davis_ag.benchmark.results import (
    EvaluationResults,
    PairedGap,
    PolicyResult,
    SceneIdentity,
    load_results,
    split_text,
    table_number,
)
from davis_ag.benchmark.summaries import PAIRED_BASELINES
from davis_ag.errors import UserError


@dataclass
class Row:
    """One method of the leaderboard: its name, the file it comes from and its results."""

    name: str
    base: str
    file: Path
    results: EvaluationResults
    policy: PolicyResult
    gaps: dict[str, PairedGap | None]
    #: How a maintainer checked the row (``compare --verify``): ``re-run``, ``ours``, ``replayed``; "" unchecked.
    check: str = ""


def _identity(results: EvaluationResults) -> dict[str, object]:
    """What must agree for two results to be ranked together, by what a message calls it."""
    p = results.protocol
    return {
        "protocol version": p.version,
        "environment": p.environment,
        "scenario": p.scenario,
        "crop": p.crop,
        "split": p.split,
        # Another rule's test side holds other starts (and scenes): named before the scenes it moves.
        # A file from before the rules split by scenes.
        "split rule": p.split_rule or "scenes",
        "test scenes": tuple(p.scenes),
        # After the split and its scenes: another split plays other scenes, and is named as such.
        "dataset": _evaluated_scenes(results),
        "tau": p.tau,
        "start rule": p.start_rule,
        "eligible starts": p.starts,
        # A robot changes which moves exist: rows under different robots (or none) are not one table.
        "robot": (p.robot["name"], p.robot["digest"]) if p.robot else None,
    }


def _evaluated_scenes(results: EvaluationResults) -> list[SceneIdentity] | None:
    """The identities of the scenes the file evaluated, by id (None where it records no dataset).

    A dataset grows: the crops run adds a group at a time, and a file made before a group was
    added was refused beside one made after, though both played the same scenes.
    """
    if results.dataset is None:
        return None
    played = set(results.protocol.scenes)
    return sorted((s for s in results.dataset.scenes if s.id in played), key=lambda s: s.id)


def check_comparable(files: list[tuple[Path, EvaluationResults]]) -> None:
    """Refuse results that measure different things (see the module docstring).

    Raises:
        UserError: one line naming the two files and what differs.
    """
    (first, base), others = files[0], files[1:]
    if base.protocol.version == 0:
        raise UserError(
            f"{first} was written before results files had a protocol version: evaluate again "
            "with this davis-ag to rank it"
        )
    if base.dataset is None:
        raise UserError(f"{first} does not record its dataset's identity: evaluate again with this davis-ag to rank it")
    wanted = _identity(base)
    for path, results in others:
        found = _identity(results)
        for key, value in wanted.items():
            if key == "dataset" and found[key] != value and results.dataset is not None:
                theirs, ours = _evaluated_scenes(results), _evaluated_scenes(base)
                assert theirs is not None and ours is not None  # both record their dataset (above)
                difference = _scene_difference(theirs, ours)
                raise UserError(f"{path} and {first} differ in dataset: {difference}")
            if found[key] != value:
                raise UserError(
                    f"{path} and {first} differ in {key} ({_shown(found[key])} against {_shown(value)}): "
                    "results of different datasets, splits, split rules or protocol versions cannot be ranked together"
                )


def _scene_difference(found: list[SceneIdentity], wanted: list[SceneIdentity]) -> str:
    """Where two files' scenes part, in words, with what to do."""
    theirs, ours = {s.id: s for s in found}, {s.id: s for s in wanted}
    if set(theirs) != set(ours):
        only = sorted(set(theirs) ^ set(ours))
        return f"{len(only)} scene(s) are in one only ({only[0]}, ...); results of different datasets cannot be ranked together"
    for scene_id in sorted(ours):
        a, b = theirs[scene_id], ours[scene_id]
        if a.seed != b.seed:
            return f"scene {scene_id} has seed {a.seed} against {b.seed}; results of different datasets cannot be ranked together"
        if (a.drawn is None) != (b.drawn is None) and a.code and b.code:
            return (
                f"one was written before results files recorded how each scene was drawn (scene {scene_id}); "
                "evaluate it again with this davis-ag to rank them together"
            )
        if a.drawn != b.drawn:
            return (
                f"scene {scene_id} was drawn otherwise (image size, renderer, plants, appearance or grid); "
                "results of different datasets cannot be ranked together"
            )
        if a.code != b.code:
            return (
                f"scene {scene_id} was made by {a.code} against {b.code}; results of different datasets "
                "cannot be ranked together (davis-ag verify SCENE says whether today's code makes it the same)"
            )
    return "results of different datasets cannot be ranked together"


def _shown(value: Any) -> Any:
    """A scene list as its length, anything else as it is (for one line)."""
    return f"{len(value)} scene(s)" if isinstance(value, tuple) else value


def _same_episodes(a: EvaluationResults, b: EvaluationResults) -> bool:
    pa, pb = a.protocol, b.protocol
    return (pa.seed, pa.sessions, pa.episodes) == (pb.seed, pb.sessions, pb.episodes)


def _gap(
    row_results: EvaluationResults, policy: PolicyResult, baseline: str, files: list[tuple[Path, EvaluationResults]]
) -> PairedGap | None:
    """The row's gap to ``baseline``: its own file's, else across files that played the same episodes
    (and so for a file from before the interval over scenes, when it kept its episodes)."""
    from davis_ag.benchmark.paired import lacks_scene_interval, paired_gap

    own = policy.paired.get(baseline)
    if own is not None and (policy.episodes is None or not lacks_scene_interval(own.model_dump())):
        return own
    if policy.episodes is None:
        return None
    for _, other in files:
        theirs = other.policies.get(baseline)
        if theirs is not None and theirs.episodes and _same_episodes(row_results, other):
            try:
                gap = paired_gap(
                    [e.model_dump() for e in policy.episodes],
                    [e.model_dump() for e in theirs.episodes],
                    seed=row_results.protocol.seed,
                )
            except ValueError:  # not the same starts after all
                continue
            return PairedGap.model_validate(asdict(gap))
    return None


def leaderboard(paths: list[str | os.PathLike[str]]) -> list[Row]:
    """The rows of the leaderboard of some results files, best OER_tau first.

    A method in several files with the same numbers and code (a baseline evaluated again on the
    same episodes) is one row; a name with other code gets its code's digest beside it, one with
    the same code and other numbers its file's name.

    Raises:
        UserError: for an unreadable file or results that cannot be ranked together.
    """
    if not paths:
        raise UserError("give at least one RESULTS.json")
    files = [(Path(p), load_results(p)) for p in paths]
    check_comparable(files)
    rows: list[Row] = []
    for path, results in files:
        for name, policy in results.policies.items():
            same = [r for r in rows if r.base == name]
            if any(_same_row(r.policy, policy) for r in same):
                continue
            label = name
            digest = policy.digest
            if same and digest is not None and all(_code(r.policy) != digest.sha256 for r in same):
                label = f"{name} (code {digest.short()})"
            elif same:
                label = f"{name} ({path.name})"
            gaps = {b: _gap(results, policy, b, files) for b in PAIRED_BASELINES if b != name}
            rows.append(Row(label, name, path, results, policy, gaps))
    return sorted(rows, key=lambda r: -r.policy.oer_tau.mean)


def _code(policy: PolicyResult) -> str | None:
    return policy.digest.sha256 if policy.digest is not None else None


def _same_row(a: PolicyResult, b: PolicyResult) -> bool:
    """One method evaluated twice: the same numbers, and the same code where both record it."""
    same_code = a.digest is None or b.digest is None or _code(a) == _code(b)
    return a.oer_tau == b.oer_tau and a.reward == b.reward and same_code


def _gap_cell(gap: PairedGap | None) -> str:
    if gap is None:
        return "-"
    over_scenes = gap.scenes_text()
    return gap.text() + (f" scenes {over_scenes}" if over_scenes else "")


def format_leaderboard(rows: list[Row]) -> str:
    """The leaderboard as a Markdown page: what the numbers rest on, then the ranked table."""
    protocol = rows[0].results.protocol
    sampling = sorted({split_text(r.results.protocol) for r in rows})
    # Files ranked together played the same scenes; a dataset that grew since holds others too.
    datasets = {r.results.dataset.fingerprint: len(r.results.dataset.scenes) for r in rows if r.results.dataset}
    held = ", ".join(f"{fingerprint} ({count} scenes)" for fingerprint, count in datasets.items())
    baselines = [b for b in PAIRED_BASELINES if any(r.gaps.get(b) for r in rows)]
    checked = any(r.check for r in rows)
    lines = [
        f"# Leaderboard: {protocol.scenario.upper()}{' ' + protocol.crop if protocol.crop else ''}, "
        f"{protocol.environment}, {protocol.split} split",
        "",
        "What the numbers rest on: " + "; ".join(sampling) + ". "
        f"Dataset{'s' if len(datasets) > 1 else ''} {held}, protocol version {protocol.version}.",
        "",
        "| Rank | Method | OER_tau | Cum. reward | Ep. length | "
        + " | ".join(f"Gap to {b} [95 %]" for b in baselines)
        + (" | " if baselines else "")
        + "Code | File |"
        + (" Checked |" if checked else ""),
        "|---:|---|---:|---:|---:|" + "---:|" * len(baselines) + "---|---|" + ("---|" if checked else ""),
    ]
    for rank, row in enumerate(rows, 1):
        p = row.policy
        cells = [str(rank), row.name] + [
            f"{table_number(m.mean)} ±{table_number(m.std)}" for m in (p.oer_tau, p.reward, p.length)
        ]
        code = f"`{p.digest.short()}`" if p.digest is not None else "-"
        cells += [_gap_cell(row.gaps.get(b)) for b in baselines] + [code, row.file.name]
        cells += [row.check or "-"] if checked else []
        lines.append("| " + " | ".join(cells) + " |")
    lines += [
        "",
        "Mean ± std over sessions. Gap: mean OER_tau minus the baseline's on the same episodes, with the "
        "95 % bootstrap interval over episodes (would it hold on other starts of these scenes?) and, after "
        f"`scenes`, over the test scenes resampled (would it hold on other scenes like these? coarse below "
        f"{FEW_SCENES} scenes); `-`: the baseline itself, or a method that did not play the same episodes. "
        "Code: the first digits of the SHA-256 of what played (the model's zip, the policy's source file; "
        "`-`: results from before digests), recorded with davis-ag's version and commit."
        + (
            " Checked (`compare --verify`): `re-run`, its code played every episode again with the same "
            "actions; `ours`, a davis-ag baseline, its episodes replayed; `replayed`, its episodes replayed "
            "on the dataset but its code not run."
            if checked
            else ""
        ),
    ]
    return "\n".join(lines) + "\n"
