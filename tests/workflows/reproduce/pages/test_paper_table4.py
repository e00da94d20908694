"""Table 4's numbers meet the orderings section VI reads from them; a reversed step fails."""

from __future__ import annotations

from dataclasses import replace

import pytest

from davis_ag.workflows.reproduce.pages.paper_table4 import (
    PAPER_ORDERINGS,
    PAPER_TABLE4,
    PAPER_TABLE4_STD,
    ordering_holds,
    paper_cells,
)


@pytest.mark.parametrize("scenario", ["sp", "mp"])
def test_table_4_meets_the_orderings_section_vi_reads_from_it(scenario: str) -> None:
    # Table 4: SP .520 (A2C) > .438 ± .101 (Rand) ~ .433 ± .007 (LRD) > .371 (UDD);
    # MP .369 > .340 (Rand) > .316 ± .008 (LRD) ~ .313 ± .006 (UDD).
    cells = paper_cells(scenario)
    assert {name: cell.mean for name, cell in cells.items()} == PAPER_TABLE4[scenario]["oer_tau"]
    assert {name: cell.std for name, cell in cells.items()} == PAPER_TABLE4_STD[scenario]["oer_tau"]
    assert ordering_holds(PAPER_ORDERINGS[scenario], cells) is True


def test_an_ordering_fails_where_a_step_is_reversed_or_apart() -> None:
    stats = paper_cells("sp")
    stats["A2C"] = replace(stats["A2C"], mean=0.40)  # below Rand
    assert ordering_holds(PAPER_ORDERINGS["sp"], stats) is False
    stats = paper_cells("mp")
    stats["UDD"] = replace(stats["UDD"], mean=0.2)  # LRD ~ UDD no longer: .116 apart, stds .014
    assert ordering_holds(PAPER_ORDERINGS["mp"], stats) is False
    del stats["A2C"]
    assert ordering_holds(PAPER_ORDERINGS["mp"], stats) is None
