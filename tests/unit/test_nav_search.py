"""The global planner's math against plain references (issue 24: pin it so a changed
step cost, heuristic, neighbour rule or pooling fails a unit test): A* finds paths as
short as Dijkstra's on the same graph, proves "no path" exactly when there is none,
stops at its cap without claiming a proof; the pooled grid is the block maximum and the
best point its first argmax; the free threshold is the documented formula."""

from __future__ import annotations

import heapq
import itertools
import math

import numpy as np
import pytest
from grid_search import astar

from otonav.nav._global_path import AstarSearch
from otonav.nav._plan_grid import best_points, free_threshold, pooled

pytestmark = pytest.mark.unit

_STEPS = [(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if dr or dc]


def _ok(free: np.ndarray, cell: tuple[int, int], ends: set[tuple[int, int]]) -> bool:
    r, c = cell
    rows, cols = free.shape
    return 0 <= r < rows and 0 <= c < cols and (bool(free[r, c]) or cell in ends)


def _dijkstra(
    free: np.ndarray, penalty: np.ndarray, start: tuple[int, int], goal: tuple[int, int]
) -> float:
    """Cheapest cost by the documented rules: 1 per straight step, sqrt 2 per diagonal
    with both side cells free, plus the entered cell's penalty; start and goal free.
    (A* searches from the goal: it is called with the two swapped.)"""
    ends = {start, goal}
    best = {start: 0.0}
    heap = [(0.0, start)]
    while heap:
        cost, cell = heapq.heappop(heap)
        if cell == goal:
            return cost
        if cost > best[cell]:
            continue
        for dr, dc in _STEPS:
            n = (cell[0] + dr, cell[1] + dc)
            if not _ok(free, n, ends):
                continue
            if (
                dr
                and dc
                and not (
                    _ok(free, (cell[0] + dr, cell[1]), ends)
                    and _ok(free, (cell[0], cell[1] + dc), ends)
                )
            ):
                continue
            c2 = cost + (math.sqrt(2.0) if dr and dc else 1.0) + float(penalty[n])
            if c2 < best.get(n, math.inf):
                best[n] = c2
                heapq.heappush(heap, (c2, n))
    return math.inf


def _cost_along(cells: tuple[tuple[int, int], ...], penalty: np.ndarray) -> float:
    cost = 0.0
    for a, b in itertools.pairwise(cells):
        diagonal = a[0] != b[0] and a[1] != b[1]
        cost += (math.sqrt(2.0) if diagonal else 1.0) + float(penalty[b])
    return cost


def test_astar_is_as_short_as_dijkstra_and_proves_no_path_exactly() -> None:
    rng = np.random.default_rng(11)
    found = proven = 0
    for _ in range(120):
        n, m = (int(v) for v in rng.integers(4, 24, 2))
        free = rng.random((n, m)) > rng.uniform(0.1, 0.45)
        penalty = (rng.random((n, m)) * rng.choice([0.0, 2.0])).astype(np.float32)
        start = (int(rng.integers(n)), int(rng.integers(m)))
        goal = (int(rng.integers(n)), int(rng.integers(m)))
        result = astar(free, penalty, start, goal)
        # The search runs from the goal: Dijkstra from the goal to the start.
        want = _dijkstra(free, penalty, goal, start)
        if math.isinf(want):
            assert not result.found
            assert result.exhausted
            assert math.isinf(result.cost)
            proven += 1
            continue
        found += 1
        assert result.found
        assert not result.exhausted
        cells = result.cells
        assert cells[0] == start
        assert cells[-1] == goal
        assert result.cost == pytest.approx(want, abs=1e-9)
        ends = {start, goal}
        for a, b in itertools.pairwise(cells):
            dr, dc = b[0] - a[0], b[1] - a[1]
            assert (dr, dc) in _STEPS
            assert _ok(free, b, ends)
            if dr and dc:  # no corner cutting
                assert _ok(free, (a[0] + dr, a[1]), ends)
                assert _ok(free, (a[0], a[1] + dc), ends)
        assert _cost_along(cells[::-1], penalty) == pytest.approx(result.cost, abs=1e-9)
        assert 0 < result.expansions <= int(np.count_nonzero(free)) + 2
    assert found > 40
    assert proven > 10


def test_a_search_cut_at_its_cap_claims_nothing() -> None:
    free = np.ones((30, 30), dtype=np.bool_)
    free[:, 15] = False  # no way across
    zero = np.zeros((30, 30), dtype=np.float32)
    capped = astar(free, zero, (5, 2), (5, 28), max_expansions=50)
    assert (capped.found, capped.exhausted, capped.expansions) == (False, False, 50)
    full = astar(free, zero, (5, 2), (5, 28))
    assert full.exhausted
    assert full.expansions == 14 * 30
    search = AstarSearch(free, zero, (5, 2), (5, 28))
    assert search.advance(100) is None
    assert search.expansions == 100
    result = search.advance(10_000)
    assert result == full
    assert search.advance(1) is result  # over: the same result, no more work
    assert search.expansions == full.expansions


def test_an_open_grid_takes_the_octile_path_and_expands_few_cells() -> None:
    free = np.ones((40, 40), dtype=np.bool_)
    zero = np.zeros((40, 40), dtype=np.float32)
    r = astar(free, zero, (0, 0), (10, 30))
    assert r.cost == pytest.approx(20 + 10 * math.sqrt(2.0), abs=1e-9)
    assert len(r.cells) == 31
    # the heuristic leads there: ties on f go to the lowest cost so far, a band of
    # 231 cells (without it, Dijkstra would flood far more of the 1 600)
    assert r.expansions <= 240


@pytest.mark.parametrize(
    ("start", "goal", "what"),
    [((0, 9), (0, 0), "start"), ((0, 0), (-1, 0), "goal"), ((9, 0), (0, 0), "start")],
)
def test_cells_outside_the_grid_are_refused(
    start: tuple[int, int], goal: tuple[int, int], what: str
) -> None:
    free = np.ones((9, 9), dtype=np.bool_)
    with pytest.raises(ValueError, match=f"{what} .* is outside the 9 x 9 grid"):
        astar(free, np.zeros((9, 9), dtype=np.float32), start, goal)
    with pytest.raises(ValueError, match="must be one 2-D shape"):
        astar(free, np.zeros((9, 8), dtype=np.float32), (0, 0), (1, 1))


def test_the_free_threshold_is_the_documented_formula() -> None:
    assert free_threshold(0.35, 0.05) == pytest.approx(0.35 - 0.025 - 0.05 * math.sqrt(2.0))
    assert free_threshold(0.5, 0.1) == pytest.approx(0.5 - 0.05 - 0.1 * math.sqrt(2.0))


@pytest.mark.parametrize("stride", [1, 2, 3])
def test_pooling_is_the_block_maximum_and_the_best_point_its_first_argmax(stride: int) -> None:
    rng = np.random.default_rng(stride)
    fine = rng.integers(0, 4, (13, 13)).astype(np.float32)  # ties on purpose
    coarse = pooled(fine, stride)
    n = 13 // stride
    assert coarse.shape == (n, n)
    rows, cols = np.divmod(np.arange(n * n), n)
    best_r, best_c = best_points(fine, stride, rows, cols)
    for k, (r, c) in enumerate(zip(rows, cols, strict=True)):
        block = fine[r * stride : (r + 1) * stride, c * stride : (c + 1) * stride]
        assert coarse[r, c] == block.max()
        i, j = divmod(int(block.argmax()), stride)  # first on ties, row-major
        assert (best_r[k], best_c[k]) == (r * stride + i, c * stride + j)
