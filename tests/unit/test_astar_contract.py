"""A*'s documented contract beyond path length (issue 24, test rigor): the start and the
goal count as free whatever the grid says, each on its own, and its result is a frozen,
slotted value."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from grid_search import astar

from otonav.nav._global_path import AstarSearch, GridPath

pytestmark = pytest.mark.unit


@pytest.mark.parametrize("blocked", ["start", "goal", "both"])
def test_a_blocked_start_or_goal_cell_is_still_where_the_path_ends(blocked: str) -> None:
    free = np.ones((7, 7), dtype=np.bool_)
    start, goal = (3, 0), (3, 6)
    if blocked in ("start", "both"):
        free[start] = False
    if blocked in ("goal", "both"):
        free[goal] = False
    zero = np.zeros((7, 7), dtype=np.float32)
    r = astar(free, zero, start, goal)
    assert r.found
    assert (r.cells[0], r.cells[-1]) == (start, goal)
    assert r.cost == pytest.approx(6.0)
    # a blocked cell that is neither stays blocked: a wall with its only gap blocked
    wall = free.copy()
    wall[:, 3] = False
    assert astar(wall, zero, start, goal).exhausted
    search = AstarSearch(free, zero, start, goal)
    assert search.advance(1_000) == r


def test_a_grid_path_is_frozen_and_slotted() -> None:
    r = astar(np.ones((3, 3), dtype=np.bool_), np.zeros((3, 3)), (0, 0), (2, 2))
    assert isinstance(r, GridPath)
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.cost = 0.0  # type: ignore[misc]
    assert not hasattr(r, "__dict__")
