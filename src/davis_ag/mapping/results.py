"""The results file of a row-mapping evaluation: its schema (pydantic), the summaries made from its
episodes, and the checks that a reader ranks what the episodes say.

One :class:`MappingResults` is what ``davis-ag evaluate --task mapping --out RESULTS.json`` writes.
Every summary follows from the episodes (:func:`episode_metrics`, :func:`summarise`);
:func:`load_mapping_results` makes them again and refuses a file whose stored ones differ.

Per episode: ``coverage`` (the segment's fruit seen by the end, as a share), ``area`` (the mean of
the coverage after each of the budget's moves, 0 to ``budget``: the area under the coverage curve
over the budget, 1 for a policy that sees everything at once), ``reach_50`` and ``reach_80``
(whether the episode saw 50 % and 80 % of what its part of the grid can see at all, its
``part_ceiling``) and ``moves_50``/``moves_80`` (the moves it took, where it did).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Final, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from davis_ag.benchmark.results import CodeDigest, DatasetIdentity, Metric, read_results_file, table_number
from davis_ag.benchmark.summaries import session_metrics
from davis_ag.errors import UserError

#: The ``format`` field of every mapping results file.
MAPPING_FORMAT: Final = "davis-ag mapping results"
#: Bumped whenever a change to the environment or the loop would move a number.
MAPPING_PROTOCOL_VERSION = 1
#: Shares of the part's ceiling whose first reaching is timed.
MILESTONES = (0.5, 0.8)
#: The per-episode metrics every policy row summarises.
METRIC_KEYS = ("coverage", "area", "reach_50", "reach_80", "refused")


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid")


class MappingEpisode(_Model):
    """One episode: its start, what each step saw first, and the moves."""

    session: int
    scene: str
    fruit: int = Field(ge=1, description="the segment's fruit")
    part: int = Field(ge=0, description="the part of the move graph it started in (its scene's parts' index)")
    part_ceiling: int = Field(ge=0, description="fruit seen from at least one view of the start's part")
    seen_0: int = Field(ge=0, description="fruit the start view sees")
    gains: list[int] = Field(description="fruit first seen at each step")
    path: list[str]
    actions: list[int]
    seconds: float | None = None
    step_seconds: list[float] | None = Field(default=None, description="with a robot: each step's seconds")


class PartBound(_Model):
    """One part of a scene's move graph (an alley) episodes start in: its views, ceiling and budget
    bound (fruit)."""

    index: int
    views: int
    ceiling: int
    bound: int
    exact: bool


class SceneSegment(_Model):
    """A scene's segment: its fruit, the grid's ceiling and each part's bound."""

    fruit: int
    ceiling: int
    parts: list[PartBound]


class MappingProtocol(_Model):
    """The protocol as run (as TVM-v0's: episode ``e`` of session ``s`` resets with
    ``SeedSequence([seed, s])``'s ``e``-th state, the policy with ``SeedSequence([seed, s, 1])``'s)."""

    version: int = Field(ge=1, le=MAPPING_PROTOCOL_VERSION)
    environment: Literal["davis_ag/RowMapping-v0"] = "davis_ag/RowMapping-v0"
    scenario: Literal["sp", "mp", "row"]
    crop: str | None = None
    split: str
    budget: int = Field(ge=1)
    budget_s: float | None = None
    seen_fraction: float = Field(gt=0, le=1)
    episodes: int = Field(ge=1)
    sessions: int = Field(ge=1)
    seed: int
    scenes: list[str]
    dataset: str
    actions: list[str]
    robot: dict[str, str] | None = None


class MappingPolicyResult(_Model):
    """One policy's row."""

    coverage: Metric
    area: Metric
    reach_50: Metric
    reach_80: Metric
    refused: Metric
    moves_50: float | None = Field(default=None, description="mean moves to 50 % of the part's ceiling, where reached")
    moves_80: float | None = None
    seconds_50: float | None = Field(default=None, description="with a robot: mean seconds to 50 %, where reached")
    seconds_80: float | None = None
    seconds: Metric | None = None
    bound: float = Field(description="mean over its episodes of the start part's budget bound, as a share")
    part_ceiling: float = Field(description="mean over its episodes of the start part's ceiling, as a share")
    source: str | None = None
    digest: CodeDigest | None = None
    episodes: list[MappingEpisode]


class MappingResults(_Model):
    """A row-mapping evaluation: protocol, dataset identity, the split's segments, one row per policy."""

    format: Literal["davis-ag mapping results"] = MAPPING_FORMAT
    protocol: MappingProtocol
    dataset: DatasetIdentity | None = None
    code: str | None = None
    segments: dict[str, SceneSegment]
    policies: dict[str, MappingPolicyResult] = Field(min_length=1)

    def as_json(self) -> dict[str, Any]:
        """The results as the JSON file holds them."""
        return self.model_dump(mode="json", exclude_none=True)

    def write(self, path: str | os.PathLike[str]) -> Path:
        """Write the results as indented JSON, atomically."""
        from davis_ag.atomic_files import write_json_atomic

        return write_json_atomic(path, self.as_json(), indent=2)


def coverage_curve(episode: MappingEpisode, budget: int) -> np.ndarray:
    """Fruit seen after 0, 1, ..., ``budget`` moves (an episode the robot's seconds ended early
    keeps its last value)."""
    seen = episode.seen_0 + np.concatenate([[0], np.cumsum(episode.gains, dtype=np.int64)])
    if len(seen) < budget + 1:
        seen = np.concatenate([seen, np.full(budget + 1 - len(seen), seen[-1])])
    return seen[: budget + 1]


def episode_metrics(episode: MappingEpisode, budget: int) -> dict[str, Any]:
    """The per-episode metrics (see the module docstring)."""
    curve = coverage_curve(episode, budget)
    metrics: dict[str, Any] = {
        "session": episode.session,
        "coverage": float(curve[-1] / episode.fruit),
        "area": float(curve.mean() / episode.fruit),
        "refused": sum(a == b for a, b in zip(episode.path, episode.path[1:])),
    }
    for share in MILESTONES:
        key = f"{round(share * 100)}"
        goal = share * episode.part_ceiling
        reached = np.flatnonzero(curve >= goal) if episode.part_ceiling else np.zeros(0, dtype=np.int64)
        metrics[f"reach_{key}"] = float(len(reached) > 0)
        metrics[f"moves_{key}"] = int(reached[0]) if len(reached) else None
        if episode.step_seconds is not None:  # the seconds of the moves made until then
            spent = float(np.sum(episode.step_seconds[: int(reached[0])])) if len(reached) else None
            metrics[f"seconds_{key}"] = spent
    if episode.seconds is not None:
        metrics["seconds"] = float(episode.seconds)
    return metrics


def summarise(
    episodes: list[MappingEpisode], budget: int, sessions: int, segments: dict[str, SceneSegment]
) -> dict[str, Any]:
    """A policy row's summaries from its episodes (everything but source, digest and episodes)."""
    records = [episode_metrics(e, budget) for e in episodes]
    keys = METRIC_KEYS + (("seconds",) if all("seconds" in r for r in records) else ())
    row: dict[str, Any] = session_metrics(records, keys, sessions)
    for share in MILESTONES:
        for unit in ("moves", "seconds"):
            key = f"{unit}_{round(share * 100)}"
            values = [r[key] for r in records if r.get(key) is not None]
            row[key] = float(np.mean(values)) if values else None
    row["bound"] = float(np.mean([_start_part(e, segments).bound / e.fruit for e in episodes]))
    row["part_ceiling"] = float(np.mean([e.part_ceiling / e.fruit for e in episodes]))
    return row


def _start_part(episode: MappingEpisode, segments: dict[str, SceneSegment]) -> PartBound:
    """The part of its scene's move graph an episode started in.

    Raises:
        UserError: when the file's segments do not list it.
    """
    segment = segments.get(episode.scene)
    part = next((p for p in segment.parts if p.index == episode.part), None) if segment is not None else None
    if part is None:
        raise UserError(
            f"an episode of scene {episode.scene} starts in part {episode.part}, which the file does not list"
        )
    return part


def check_mapping_summaries(results: MappingResults, source: str) -> None:
    """Make every summary again from the episodes; a stored one that differs is refused.

    Raises:
        UserError: naming the policy and the field.
    """
    budget, sessions = results.protocol.budget, results.protocol.sessions
    for name, row in results.policies.items():
        fresh = summarise(row.episodes, budget, sessions, results.segments)
        stored = row.model_dump(exclude={"source", "digest", "episodes"}, exclude_none=True)
        for key, value in fresh.items():
            if value is None and key not in stored:
                continue
            if not _close(stored.get(key), value):
                raise UserError(
                    f"{source}: policy {name}'s {key} is not what its episodes give; the file was edited: "
                    "evaluate again"
                )


def _close(a: Any, b: Any) -> bool:
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_close(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_close(x, y) for x, y in zip(a, b))
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return abs(float(a) - float(b)) <= 1e-9 * max(1.0, abs(float(b)))
    return a == b


def is_mapping_results(path: str | os.PathLike[str]) -> bool:
    """Whether a JSON file says it holds mapping results (anything unreadable: False)."""
    try:
        with open(path, "rb") as handle:
            head = handle.read(4096).decode("utf-8", "replace")
    except OSError:
        return False
    return f'"format": "{MAPPING_FORMAT}"' in head or f'"format":"{MAPPING_FORMAT}"' in head


def load_mapping_results(path: str | os.PathLike[str]) -> MappingResults:
    """Read a mapping results file and check every summary against its episodes.

    Raises:
        UserError: when the file is missing, not JSON, not mapping results, or edited.
    """
    path = Path(path)
    results = read_results_file(path, MappingResults, "mapping results", "davis-ag evaluate --task mapping")
    check_mapping_summaries(results, str(path))
    return results


def mapping_table(results: MappingResults) -> str:
    """The results as a Markdown table: every policy by coverage, then the bound and the ceiling."""
    protocol = results.protocol
    robot = protocol.robot is not None
    head = "| policy | coverage | curve area | 50 % of reachable | moves to 50 % | 80 % of reachable | moves to 80 % |"
    head += " robot seconds | seconds to 50 % | seconds to 80 % |" if robot else ""
    rows = [head, "|" + "---|" * (head.count("|") - 1)]
    ordered = sorted(results.policies.items(), key=lambda item: -item[1].coverage.mean)

    def moves(value: float | None) -> str:
        return f"{value:.1f}" if value is not None else "never"

    def share(value: float) -> str:  # one decimal: 1 episode in 600 is not 0 %
        return f"{value:.1%}"

    for name, row in ordered:
        cells = [
            name,
            f"{table_number(row.coverage.mean)} ± {table_number(row.coverage.std)}",
            table_number(row.area.mean),
            share(row.reach_50.mean),
            moves(row.moves_50),
            share(row.reach_80.mean),
            moves(row.moves_80),
        ]
        if robot:
            cells.append(f"{row.seconds.mean:.1f}" if row.seconds is not None else "-")
            cells += [f"{v:.1f}" if v is not None else "never" for v in (row.seconds_50, row.seconds_80)]
        rows.append("| " + " | ".join(cells) + " |")
    any_row = next(iter(results.policies.values()))
    exact = all(part.exact for s in results.segments.values() for part in s.parts)
    bound_name = f"Bound: the best {protocol.budget + 1} views{'' if exact else ' (proven upper bound)'}"
    blank = " | ".join(["-"] * (len(rows[0].split("|")) - 4))
    rows.append(f"| {bound_name} | {table_number(any_row.bound)} | {blank} |")
    rows.append(f"| Ceiling: every view of the start's alley | {table_number(any_row.part_ceiling)} | {blank} |")
    fruit = sum(s.fruit for s in results.segments.values())
    ceiling = sum(s.ceiling for s in results.segments.values())
    reached = " the robot reaches" if robot else ""
    rows.append(f"| Ceiling: every view of the grid{reached} | {table_number(ceiling / fruit)} | {blank} |")
    return "\n".join(rows)
