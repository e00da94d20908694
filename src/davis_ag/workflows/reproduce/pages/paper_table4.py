"""Table 4 of the paper and the orderings section VI reads from it: the numbers every results
page and README block sets ours beside, owned here alone.

Every value is the paper's (Table 4, section VI); tests pin them against the paper, never
against our runs.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Protocol

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


class MeanStd(Protocol):
    """A mean and its std over sessions: a measured :class:`~davis_ag.benchmark.results.Metric`,
    or one of Table 4's cells (:class:`PaperCell`)."""

    @property
    def mean(self) -> float:
        """The mean over sessions."""
        ...

    @property
    def std(self) -> float:
        """The std of the session means."""
        ...


@dataclass(frozen=True)
class PaperCell:
    """One of Table 4's numbers: the mean and std over the paper's three sessions."""

    mean: float
    std: float


def paper_cells(scenario: str, metric: str = "oer_tau") -> dict[str, PaperCell]:
    """Table 4's column of one scenario and metric, each policy's mean with its std.

    Args:
        scenario: ``sp`` or ``mp``.
        metric: ``oer_tau``, ``reward`` or ``length``.

    Returns:
        Per policy, its cell.
    """
    return {
        name: PaperCell(value, PAPER_TABLE4_STD[scenario][metric][name])
        for name, value in PAPER_TABLE4[scenario][metric].items()
    }


def ordering_failures(order: tuple[str, ...], stats: Mapping[str, MeanStd]) -> list[str] | None:
    """The steps of an ordering such as ``A2C > Rand ~ LRD > UDD`` that measured means and stds break.

    ``a > b`` holds when a's mean exceeds b's; ``a ~ b`` when the means differ by no more than the
    two standard deviations (over sessions) added.

    Args:
        order: The ordering, policies and relations in turn.
        stats: Each policy's mean and std of the metric ordered (OER_tau).

    Returns:
        One sentence per broken step (empty when the ordering holds); None when a policy in the
        ordering was not measured.
    """
    if any(name not in stats for name in order[::2]):
        return None
    failures = []
    for left, relation, right in zip(order[0::2], order[1::2], order[2::2]):
        a, b = stats[left], stats[right]
        if relation == ">" and not a.mean > b.mean:
            failures.append(f"{left} > {right} fails: {cell(a.mean)} is not above {cell(b.mean)}")
        gap, spread = abs(a.mean - b.mean), a.std + b.std
        if relation == "~" and gap > spread:
            failures.append(
                f"{left} ~ {right} fails: {cell(a.mean)} and {cell(b.mean)} are "
                f"{cell(gap)} apart, more than their stds added ({cell(spread)})"
            )
    return failures


def ordering_holds(order: tuple[str, ...], stats: Mapping[str, MeanStd]) -> bool | None:
    """Whether an ordering holds for measured means and stds (:func:`ordering_failures`).

    Args:
        order: The ordering, policies and relations in turn.
        stats: Each policy's mean and std of the metric ordered.

    Returns:
        True or False; None when a policy in the ordering was not measured.
    """
    failures = ordering_failures(order, stats)
    return None if failures is None else not failures


def cell(value: float | None) -> str:
    """Table 4 style: three decimals, no leading zero below 1 (``.433``)."""
    if value is None:
        return "–"
    text = f"{value:.3f}"
    return text[1:] if text.startswith("0.") else text


def signed(value: float) -> str:
    """A gap in Table 4 style with its sign (``+.013``, ``-.027``)."""
    return ("+" if value >= 0 else "-") + cell(abs(value))
