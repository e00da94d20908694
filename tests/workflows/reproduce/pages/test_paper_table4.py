"""Table 4's numbers meet the orderings section VI reads from them; a reversed step fails."""

from __future__ import annotations

import pytest

from davis_ag.workflows.reproduce.pages.paper_table4 import (
    PAPER_ORDERINGS,
    PAPER_TABLE4,
    PAPER_TABLE4_STD,
    ordering_holds,
)


def paper_stats(scenario: str) -> dict:
    return {
        name: {"oer_tau": {"mean": mean, "std": PAPER_TABLE4_STD[scenario]["oer_tau"][name]}}
        for name, mean in PAPER_TABLE4[scenario]["oer_tau"].items()
    }


@pytest.mark.parametrize("scenario", ["sp", "mp"])
def test_table_4_meets_the_orderings_section_vi_reads_from_it(scenario: str) -> None:
    # Table 4: SP .520 (A2C) > .438 ± .101 (Rand) ~ .433 ± .007 (LRD) > .371 (UDD);
    # MP .369 > .340 (Rand) > .316 ± .008 (LRD) ~ .313 ± .006 (UDD).
    assert ordering_holds(PAPER_ORDERINGS[scenario], paper_stats(scenario)) is True


def test_an_ordering_fails_where_a_step_is_reversed_or_apart() -> None:
    stats = paper_stats("sp")
    stats["A2C"]["oer_tau"]["mean"] = 0.40  # below Rand
    assert ordering_holds(PAPER_ORDERINGS["sp"], stats) is False
    stats = paper_stats("mp")
    stats["UDD"]["oer_tau"]["mean"] = 0.2  # LRD ~ UDD no longer: .116 apart, stds .014
    assert ordering_holds(PAPER_ORDERINGS["mp"], stats) is False
    del stats["A2C"]
    assert ordering_holds(PAPER_ORDERINGS["mp"], stats) is None
