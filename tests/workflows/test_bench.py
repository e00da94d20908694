"""The bench's paper-scale projection counts the paper's dataset and adds up its costs."""

from __future__ import annotations

import pytest

from davis_ag.workflows.bench_report import POOL_GAIN, projection

CROPS = ("strawberry", "tomato", "vine")


def test_the_projection_counts_the_papers_images_and_farms() -> None:
    report = projection({c: 1.0 for c in CROPS}, {c: 0.0 for c in CROPS})
    # Section III-D: ">502K images from over 632 virtual farms"; Table 3's counts add up to 502,542.
    assert report["images"] == 502_542 and report["scenes"] == 632
    assert report["hours_one_machine_one_process"] == pytest.approx(502_542 / 3600, abs=0.1)
    assert report["hours_one_machine"] == pytest.approx(502_542 / 3600 / POOL_GAIN, abs=0.1)


def test_the_grow_and_draw_bound_is_below_the_whole_cost() -> None:
    ours = projection(
        {c: 0.5 for c in CROPS}, {c: 30.0 for c in CROPS}, {c: 0.2 for c in CROPS}, {c: 20.0 for c in CROPS}
    )
    assert 0 < ours["hours_one_machine_grow_and_draw_only"] < ours["hours_one_machine"]
    assert "hours_one_machine_grow_and_draw_only" not in projection({c: 0.5 for c in CROPS}, {c: 30.0 for c in CROPS})


def test_a_measured_pool_gain_replaces_the_helios_one() -> None:
    costs = ({c: 1.0 for c in CROPS}, {c: 0.0 for c in CROPS})
    assert projection(*costs, gain=2.0)["hours_one_machine"] == pytest.approx(502_542 / 3600 / 2, abs=0.1)
    assert "measured by this bench" in projection(*costs, gain=2.0)["assumptions"]
