"""Section V-C and V-D's episode rules that every environment shares: the start rule and the reward."""

from __future__ import annotations

from typing import overload

import numpy as np

#: Section V-D: an episode starts on a target with OER below this.
MAX_START_OER = 0.4


@overload
def can_start(oer: float, max_start_oer: float = MAX_START_OER) -> bool: ...
@overload
def can_start(oer: np.ndarray, max_start_oer: float = MAX_START_OER) -> np.ndarray: ...
def can_start(oer: float | np.ndarray, max_start_oer: float = MAX_START_OER) -> bool | np.ndarray:
    """Section V-D's start rule: a fruit may be an episode's target when its OER is below the
    limit (a float, or an array of them); the grid and the continuous environments share it."""
    return oer < max_start_oer


def episode_reward(oer_0: float, oer_end: float) -> float:
    """Section V-C's reward at an episode's end: ``max(OER_end - OER_0, 0) ** 2``."""
    return float(max(oer_end - oer_0, 0.0) ** 2)


#: How ``reset`` draws a start: ``pairs`` uniform over every eligible (scene, view, target),
#: ``scene`` uniform over scenes, then views, then targets (see the module docstring).
START_RULES = ("pairs", "scene")
