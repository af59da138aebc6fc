"""The tests' shorthands for the navigator's grids: a one-call A*
(:class:`~otonav.nav._global_path.AstarSearch` run to the end; the navigator always runs
it in budgets), and a :class:`~otonav.nav._costmap.ClearanceMap`'s cells of points."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from otonav.nav._costmap import ClearanceMap
from otonav.nav._global_path import MAX_EXPANSIONS, AstarSearch, GridPath


def astar(
    free: NDArray[np.bool_],
    penalty: NDArray[np.floating[Any]],
    start: tuple[int, int],
    goal: tuple[int, int],
    *,
    max_expansions: int = MAX_EXPANSIONS,
) -> GridPath:
    search = AstarSearch(free, penalty, start, goal, max_expansions=max_expansions)
    result = search.advance(max_expansions)
    assert result is not None  # the budget is the cap: the search ended
    return result


def mark(m: ClearanceMap, xy: NDArray[np.float64]) -> int:
    """``m.mark_xy`` of ``(N, 2)`` points."""
    return m.mark_xy(xy[:, 0], xy[:, 1])


def cell_of(
    m: ClearanceMap, x: NDArray[np.float64], y: NDArray[np.float64]
) -> tuple[NDArray[np.intp], NDArray[np.intp], NDArray[np.bool_]]:
    """Row (y) and column (x) indices of points in ``m``, and which are inside it (the
    arithmetic of ``mark_xy``)."""
    inv = 1.0 / m.resolution
    col = np.floor((x - m.origin_x) * inv).astype(np.intp)
    row = np.floor((y - m.origin_y) * inv).astype(np.intp)
    inside = (col >= 0) & (col < m.size) & (row >= 0) & (row < m.size)
    return row, col, inside
