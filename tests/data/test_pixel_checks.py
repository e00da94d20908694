"""Pixel checks: the one-pass median depth of each fruit is the per-fruit median it replaces."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from davis_ag.data.pixel_checks import _median_depth_by_fruit
from davis_ag.data.reader import NO_FRUIT

SHAPE = (6, 9)


@settings(max_examples=200, deadline=None)
@given(
    mask=arrays(np.uint8, SHAPE, elements=st.sampled_from([0, 1, 2, 7, NO_FRUIT])),
    depth=arrays(np.uint16, SHAPE, elements=st.integers(0, 3000)),
    asked=st.lists(st.sampled_from([0, 1, 2, 7, 9]), unique=True),
)
def test_median_depth_of_each_fruit_is_the_median_of_its_pixels_that_hit(
    mask: np.ndarray, depth: np.ndarray, asked: list[int]
) -> None:
    hit = depth > 0
    expected = {
        fruit: float(np.median(depth[(mask == fruit) & hit])) for fruit in asked if ((mask == fruit) & hit).any()
    }
    assert _median_depth_by_fruit(mask, depth, hit, asked) == expected
