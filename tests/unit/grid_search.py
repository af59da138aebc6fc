"""The tests' one-call A*: :class:`~otonav.nav._global_path.AstarSearch` run to the end
(the navigator always runs it in budgets; these tests compare against whole searches)."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

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
