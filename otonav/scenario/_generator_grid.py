"""Does a path exist for the robot, and how long is it? A grid answer, for labelling
generated worlds and checking built-in scenarios.

Pure numpy and stdlib: no MuJoCo, no actors. World frame (REP 103): x, y in metres.

1. :func:`occupancy` rasterises the world: a cell is blocked when its centre is within
   ``inflation`` of any box (exact distance to each, rotated, box) or lies outside
   the arena shrunk by ``inflation``. Inflating obstacles by the robot's radius turns
   "can the robot's disc pass" into "can a point pass" (configuration space).
2. :func:`shortest_path` searches it: A* on the 8-connected grid (octile heuristic, no
   diagonal step that cuts a blocked corner), then shortens the cell path by line of
   sight (greedy string pulling), so its length is within a few per cent of the true
   any-angle shortest path (2 % over in the unit test's wall gap) instead of the
   grid's octile length (up to 8 % longer).

The answer is conservative by one cell: a passage narrower than ``2 * inflation`` plus
about one resolution may be labelled closed.
"""

from __future__ import annotations

import heapq
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from otonav.hal import BoxObstacle

__all__ = ("Grid", "GridPath", "occupancy", "shortest_path")

_SQRT2 = math.sqrt(2.0)


CELL = 0.05
"""m, the labelling grid's cell (``WorldParams.resolution``): the generator's own, not
the localizer's map (``nav.localization.resolution``), which only happens to match."""


@dataclass(frozen=True, slots=True)
class Grid:
    """A square occupancy grid over ``[-half, half]^2`` m: ``blocked[i, j]`` is the cell
    whose centre is ``(x_of(j), y_of(i))`` (row = y, column = x)."""

    half: float
    resolution: float
    blocked: NDArray[np.bool_]

    @property
    def n(self) -> int:
        return int(self.blocked.shape[0])

    def centre(self, i: int, j: int) -> tuple[float, float]:
        return (-self.half + (j + 0.5) * self.resolution, -self.half + (i + 0.5) * self.resolution)

    def cell(self, x: float, y: float) -> tuple[int, int] | None:
        """The (row, column) holding the point (x, y), None outside the grid."""
        j = math.floor((x + self.half) / self.resolution)
        i = math.floor((y + self.half) / self.resolution)
        if 0 <= i < self.n and 0 <= j < self.n:
            return (i, j)
        return None

    def free_at(self, x: float, y: float) -> bool:
        c = self.cell(x, y)
        return c is not None and not bool(self.blocked[c])


@dataclass(frozen=True, slots=True)
class GridPath:
    """A path found on a :class:`Grid`: way-points in metres (start and goal included)
    and its length, m."""

    points: tuple[tuple[float, float], ...]
    length_m: float


def box_distances(
    xs: NDArray[np.float64], ys: NDArray[np.float64], box: BoxObstacle
) -> NDArray[np.float64]:
    """Distance (m) from every point (xs, ys) to ``box``; 0 inside (vectorised
    :meth:`BoxObstacle.distance_to`)."""
    c, s = math.cos(box.yaw), math.sin(box.yaw)
    dx, dy = xs - box.x, ys - box.y
    ex = np.maximum(np.abs(c * dx + s * dy) - box.half_x, 0.0)
    ey = np.maximum(np.abs(-s * dx + c * dy) - box.half_y, 0.0)
    return np.asarray(np.hypot(ex, ey), dtype=np.float64)


def occupancy(
    boxes: Sequence[BoxObstacle], half: float, inflation: float, resolution: float = CELL
) -> Grid:
    """The grid over the arena ``[-half, half]^2`` (m), each cell blocked when its centre
    is within ``inflation`` (m) of a box (inside one, for 0) or closer to the arena's edge."""
    if not (half > 0 and resolution > 0 and inflation >= 0):
        raise ValueError(
            f"occupancy: need half > 0, resolution > 0, inflation >= 0 "
            f"(got {half}, {resolution}, {inflation})"
        )
    n = math.ceil(2 * half / resolution)
    axis = -half + (np.arange(n, dtype=np.float64) + 0.5) * resolution
    xs, ys = np.meshgrid(axis, axis)  # xs[i, j] = axis[j], ys[i, j] = axis[i]
    edge = half - np.maximum(np.abs(xs), np.abs(ys))
    blocked = edge < inflation
    for box in boxes:
        # Cheap reject: boxes farther than their circumradius + inflation touch nothing.
        reach = math.hypot(box.half_x, box.half_y) + inflation
        if abs(box.x) - reach > half or abs(box.y) - reach > half:
            continue
        blocked |= box_distances(xs, ys, box) <= inflation
    return Grid(half=half, resolution=resolution, blocked=blocked)


def _astar(grid: Grid, start: tuple[int, int], goal: tuple[int, int]) -> list[int] | None:
    """Cells (flat indices) from start to goal on the 8-connected grid, or None."""
    n = grid.n
    free = ~grid.blocked.ravel()
    s, g = start[0] * n + start[1], goal[0] * n + goal[1]
    if not (free[s] and free[g]):
        return None
    gi, gj = goal

    def h(k: int) -> float:
        di, dj = abs(k // n - gi), abs(k % n - gj)
        return float(max(di, dj) + (_SQRT2 - 1.0) * min(di, dj))

    cost = np.full(n * n, np.inf)
    parent = np.full(n * n, -1, dtype=np.int64)
    cost[s] = 0.0
    heap: list[tuple[float, float, int]] = [(h(s), 0.0, s)]
    steps = (
        (-1, 0, 1.0),
        (1, 0, 1.0),
        (0, -1, 1.0),
        (0, 1, 1.0),
        (-1, -1, _SQRT2),
        (-1, 1, _SQRT2),
        (1, -1, _SQRT2),
        (1, 1, _SQRT2),
    )
    while heap:
        _, c, k = heapq.heappop(heap)
        if k == g:
            out = [k]
            while out[-1] != s:
                out.append(int(parent[out[-1]]))
            return out[::-1]
        if c > cost[k]:
            continue
        i, j = divmod(k, n)
        for di, dj, step in steps:
            a, b = i + di, j + dj
            if not (0 <= a < n and 0 <= b < n):
                continue
            m = a * n + b
            if not free[m]:
                continue
            if di and dj and not (free[i * n + b] and free[a * n + j]):
                continue  # a diagonal step may not cut a blocked corner
            nc = c + step
            if nc < cost[m]:
                cost[m] = nc
                parent[m] = k
                heapq.heappush(heap, (nc + h(m), nc, m))
    return None


def _visible(grid: Grid, a: tuple[float, float], b: tuple[float, float]) -> bool:
    """Every point of the segment a-b (sampled at a quarter cell) is in a free cell."""
    length = math.hypot(b[0] - a[0], b[1] - a[1])
    count = max(2, math.ceil(length / (grid.resolution / 4)) + 1)
    t = np.linspace(0.0, 1.0, count)
    xs = a[0] + t * (b[0] - a[0])
    ys = a[1] + t * (b[1] - a[1])
    j = np.floor((xs + grid.half) / grid.resolution).astype(np.int64)
    i = np.floor((ys + grid.half) / grid.resolution).astype(np.int64)
    inside = (i >= 0) & (i < grid.n) & (j >= 0) & (j < grid.n)
    if not bool(inside.all()):
        return False
    return not bool(grid.blocked[i, j].any())


def shortest_path(
    grid: Grid, start: tuple[float, float], goal: tuple[float, float]
) -> GridPath | None:
    """The shortest path (m) for a point from ``start`` to ``goal`` through free cells,
    shortened by line of sight; None when none exists (or either end is blocked)."""
    a, b = grid.cell(*start), grid.cell(*goal)
    if a is None or b is None:
        return None
    cells = _astar(grid, a, b)
    if cells is None:
        return None
    n = grid.n
    raw = [start, *(grid.centre(k // n, k % n) for k in cells[1:-1]), goal]
    # String pulling: from each kept point, walk on while the next point is in sight.
    kept = [raw[0]]
    k = 0
    while k < len(raw) - 1:
        m = k + 1
        while m + 1 < len(raw) and _visible(grid, raw[k], raw[m + 1]):
            m += 1
        kept.append(raw[m])
        k = m
    length = sum(math.dist(p, q) for p, q in itertools.pairwise(kept))
    return GridPath(points=tuple(kept), length_m=length)
