"""Section V-C and V-D's episode rules that every environment shares: the start rule, the reward,
and what a discrete action is (TVM-v0's and RowMapping-v0's)."""

from __future__ import annotations

from typing import Any, overload

import numpy as np

from davis_ag.errors import UserError

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


def discrete_action(action: Any, names: tuple[str, ...]) -> int:
    """A discrete environment's action as an index (a Python or NumPy integer, or a one-element
    integer array) into ``names``.

    Raises:
        UserError: for anything else, naming the actions.
    """
    if isinstance(action, np.ndarray) and action.size == 1:
        action = action.reshape(()).item() if action.dtype.kind in "iu" else action
    if isinstance(action, (int, np.integer)) and not isinstance(action, bool) and 0 <= int(action) < len(names):
        return int(action)
    raise UserError(f"invalid action {action!r}: expected an integer in 0..{len(names) - 1} ({', '.join(names)})")


def named_action(name: str, names: tuple[str, ...], where: str) -> int:
    """The index of the action called ``name`` (a policy may answer with names).

    Raises:
        UserError: for a name that is not one of ``names``, ``where`` saying which environment.
    """
    if name not in names:
        raise UserError(f"invalid action {name!r}: {where} has {', '.join(names)}")
    return names.index(name)
