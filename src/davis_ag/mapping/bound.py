"""The most fruit any episode of a budget can see: a maximum-coverage bound solved as an integer program.

An episode of ``B`` moves looks through at most ``B + 1`` distinct views, all in the part of the
move graph it starts in. So no policy sees more of the segment than the best ``B + 1`` views of
that part, wherever they lie and whatever order would reach them: the maximum-coverage problem

    maximise  sum_f y_f
    subject to  y_f <= sum_{v sees f} x_v,   sum_v x_v <= B + 1,   x binary,  0 <= y <= 1,

solved with SciPy's HiGHS MILP. It drops the path (which views follow which), so it bounds every
policy from above; the paths that reach it may take more moves. Solved to optimality it is exact
(``exact=True``); where the solver hits :data:`TIME_LIMIT_S` first, the value is HiGHS's proven
dual bound rounded down, still an upper bound (``exact=False``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import Bounds, LinearConstraint, milp
from scipy.sparse import csr_matrix, hstack, identity

#: Seconds the solver may spend on one bound before the proven dual bound is taken.
TIME_LIMIT_S = 20.0


@dataclass(frozen=True)
class CoverageBound:
    """The best coverage of ``views`` views.

    Attributes:
        fruit: Fruit the best views see (an upper bound when not ``exact``).
        views: The views allowed.
        exact: Whether the solver proved it optimal.
        chosen: The best views found (indices into the rows given).
    """

    fruit: int
    views: int
    exact: bool
    chosen: tuple[int, ...]


def best_views(seen: np.ndarray, views: int, time_limit_s: float = TIME_LIMIT_S) -> CoverageBound:
    """Solve the maximum-coverage bound (see the module docstring).

    Args:
        seen: ``(n_views, n_fruit)`` bool, which view sees which fruit.
        views: How many views may be chosen (``B + 1`` for a budget of ``B`` moves).
        time_limit_s: The solver's time limit.

    Returns:
        The bound.
    """
    seen = np.asarray(seen, dtype=bool)
    useful = seen.any(axis=0)
    if views <= 0 or not useful.any():
        return CoverageBound(0, max(views, 0), True, ())
    seen = seen[:, useful]
    # Views that see the same fruit are one choice: keep the first of each distinct row.
    _, first = np.unique(np.packbits(seen, axis=1), axis=0, return_index=True)
    rows = np.sort(first)
    rows = rows[seen[rows].any(axis=1)]
    matrix = seen[rows]
    if views >= len(rows):  # every useful view fits: the ceiling itself
        return CoverageBound(int(matrix.shape[1]), views, True, tuple(int(r) for r in rows))
    n_views, n_fruit = matrix.shape
    # Variables: x (views) then y (fruit). Rows: y_f - sum x_v <= 0, then sum x <= views.
    cover = hstack([-csr_matrix(matrix.T.astype(np.float64)), identity(n_fruit, format="csr")])
    count = csr_matrix(np.concatenate([np.ones(n_views), np.zeros(n_fruit)])[None, :])
    constraints = [
        LinearConstraint(cover, -np.inf, 0.0),
        LinearConstraint(count, 0.0, float(views)),
    ]
    objective = np.concatenate([np.zeros(n_views), -np.ones(n_fruit)])
    integrality = np.concatenate([np.ones(n_views), np.zeros(n_fruit)])
    result = milp(
        objective,
        constraints=constraints,
        integrality=integrality,
        bounds=Bounds(0.0, 1.0),
        options={"time_limit": time_limit_s, "disp": False},
    )
    chosen = tuple(int(rows[i]) for i in np.flatnonzero(result.x[:n_views] > 0.5)) if result.x is not None else ()
    if result.status == 0:
        return CoverageBound(round(-result.fun), views, True, chosen)
    dual = getattr(result, "mip_dual_bound", None)
    bound = int(np.floor(-dual + 1e-6)) if dual is not None and np.isfinite(dual) else int(n_fruit)
    return CoverageBound(min(bound, n_fruit), views, False, chosen)
