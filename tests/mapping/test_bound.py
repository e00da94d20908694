"""The budget's coverage bound: exactly the best choice of views, found by brute force on small cases."""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from davis_ag.mapping.bound import best_views


def _brute_force(seen: np.ndarray, k: int) -> int:
    best = 0
    for chosen in itertools.combinations(range(len(seen)), min(k, len(seen))):
        best = max(best, int(seen[list(chosen)].any(axis=0).sum()))
    return best


@settings(max_examples=40, deadline=None)
@given(
    st.integers(1, 7).flatmap(
        lambda views: st.tuples(
            st.lists(st.lists(st.booleans(), min_size=6, max_size=6), min_size=views, max_size=views),
            st.integers(0, views + 1),
        )
    )
)
def test_the_bound_is_the_best_choice_of_views(case: tuple[list[list[bool]], int]) -> None:
    rows, k = case
    seen = np.array(rows, dtype=bool)
    bound = best_views(seen, k)
    assert bound.exact
    assert bound.fruit == _brute_force(seen, k)
    if bound.chosen:  # the views it names see what it says
        assert len(bound.chosen) <= k
        assert int(seen[list(bound.chosen)].any(axis=0).sum()) == bound.fruit


def test_a_hand_made_row_has_the_bound_by_hand() -> None:
    # Five views along a row of six fruit; the end views see three each, the middle ones two.
    seen = np.array(
        [
            [1, 1, 1, 0, 0, 0],
            [0, 1, 1, 0, 0, 0],
            [0, 0, 1, 1, 0, 0],
            [0, 0, 0, 1, 1, 0],
            [0, 0, 0, 1, 1, 1],
        ],
        dtype=bool,
    )
    assert best_views(seen, 1).fruit == 3
    assert best_views(seen, 2).fruit == 6 and set(best_views(seen, 2).chosen) == {0, 4}
    assert best_views(seen, 0).fruit == 0
    assert best_views(np.zeros((3, 4), dtype=bool), 2).fruit == 0


def test_a_solver_stopped_early_still_bounds_from_above() -> None:
    rng = np.random.default_rng(0)
    seen = rng.random((60, 40)) < 0.08
    quick = best_views(seen, 5, time_limit_s=0.001)
    full = best_views(seen, 5)
    assert full.exact and full.fruit <= int(seen.any(axis=0).sum())
    assert quick.fruit == full.fruit if quick.exact else quick.fruit >= full.fruit
