"""The bounds of what the robot has observed: the convex hull of every return, every
beam's free end and every laser position, and the global planner's grid cells within a
margin of it (issue 24, ADR 0059).

Units: m; arrays are rows = y, columns = x, as in :mod:`otonav.nav._costmap`.

The clearance map counts space it has never seen as free, so a route through the
unknown is allowed and replanned once the lidar sees it blocked. Without a bound, the
unknown has no end: beyond the walls of a room lies an unknown corridor all round it,
and one wall segment hidden behind clutter is a door into it. A goal walled in against
such a wall is then unreachable only once the robot has seen every other segment of
every wall (dense walled-in worlds: the robot drove 20-25 m paths outside the arena
until its budget ran out). A planner working on a SLAM map has the same bound built in:
Nav2's global costmap takes the size of the map, which grows to the scans' extent.
Here the bound is the convex hull (not the axis-aligned box: a building need not be
square to odom) grown by ``margin``: space no beam has reached, beyond everything
observed, is not routed through. Inside the hull, unknown stays free. The navigator
applies the bound only once the goal lies inside the hull: a goal beyond everything
observed says the world goes on past it (from one room of a house, the goal two rooms
away), and then the unknown stays unbounded as before.

Cost: :meth:`ObservedHull.add` tests points against the hull's edges (a few dozen)
and rebuilds it (Andrew's monotone chain) only from the points outside;
:meth:`ObservedHull.mask` intersects the grown hull's half-planes with each row of
the grid (one numpy pass over rows x edges).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from otonav.nav._scan import ScanRays

__all__ = ("ObservedHull", "convex_hull", "free_ends")


def convex_hull(x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
    """The convex hull of points, ``(M, 2)`` counter-clockwise without repeating the
    first vertex (Andrew's monotone chain; collinear points dropped). Fewer than three
    distinct points: those points."""
    # sorted by x, then y, duplicates dropped (not np.unique: its first call imports
    # numpy.ma, ~8 ms in the first run of a process)
    order = np.lexsort((y, x))
    pts = np.stack((x[order], y[order]), axis=1)
    if pts.shape[0] > 1:
        pts = pts[np.concatenate(([True], (np.diff(pts, axis=0) != 0.0).any(axis=1)))]
    if pts.shape[0] < 3:
        return pts
    rows = pts.tolist()

    def chain(points: list[list[float]]) -> list[list[float]]:
        out: list[list[float]] = []
        for p in points:
            while len(out) >= 2:
                (ax, ay), (bx, by) = out[-2], out[-1]
                if (bx - ax) * (p[1] - ay) - (by - ay) * (p[0] - ax) > 0.0:
                    break
                out.pop()
            out.append(p)
        return out

    lower, upper = chain(rows), chain(rows[::-1])
    return np.array(lower[:-1] + upper[:-1], dtype=np.float64)


def free_ends(rays: ScanRays) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Where the beams that saw nothing within range end (``+inf``, or a finite value
    beyond ``range_max``): ``range_max`` from the laser, odom x and y arrays."""
    r = rays.ranges
    empty = np.flatnonzero((r > rays.range_max) & ~np.isnan(r))
    angles = rays.yaw + rays.angle_min + rays.angle_increment * empty
    return (
        rays.x + rays.range_max * np.cos(angles),
        rays.y + rays.range_max * np.sin(angles),
    )


class ObservedHull:
    """The convex hull of the points observed so far (grows only). Mutable, owned by
    one navigator; plain computation."""

    def __init__(self, x: float, y: float) -> None:
        self._points = np.array([[x, y]], dtype=np.float64)
        """The hull's vertices (CCW), or all points while fewer than three."""
        self.version = 0
        """Bumped whenever the hull grows (a cached mask is stale)."""

    @property
    def vertices(self) -> NDArray[np.float64]:
        """The hull's vertices, ``(M, 2)`` CCW (read-only copy)."""
        return self._points.copy()

    def add(self, x: NDArray[np.float64], y: NDArray[np.float64]) -> bool:
        """Take points (odom x and y arrays, m); True when the hull grew."""
        if x.shape[0] == 0:
            return False
        v = self._points
        if v.shape[0] >= 3:
            outside = self._outside(x, y)
            if not outside.any():
                return False
            x, y = x[outside], y[outside]
        hull = convex_hull(np.concatenate((v[:, 0], x)), np.concatenate((v[:, 1], y)))
        if hull.shape == v.shape and np.array_equal(hull, v):
            return False
        self._points = hull
        self.version += 1
        return True

    def contains(self, x: float, y: float) -> bool:
        """The point lies inside the hull (or on it); never while it has fewer than
        three vertices."""
        if self._points.shape[0] < 3:
            return False
        return not bool(self._outside(np.array([x]), np.array([y]))[0])

    def _outside(self, x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.bool_]:
        v = self._points
        a = v
        b = np.roll(v, -1, axis=0)
        ex, ey = (b - a).T
        # cross(edge, p - a) < 0: p is right of an edge of a CCW polygon, outside it
        cross = ex[None, :] * (y[:, None] - a[None, :, 1]) - ey[None, :] * (
            x[:, None] - a[None, :, 0]
        )
        outside: NDArray[np.bool_] = (cross < 0.0).any(axis=1)
        return outside

    def mask(
        self,
        origin_x: float,
        origin_y: float,
        cell: float,
        rows: int,
        cols: int,
        margin: float,
    ) -> NDArray[np.bool_]:
        """Grid cells (``rows`` x ``cols`` of ``cell`` m from the corner ``(origin_x,
        origin_y)``) whose centre lies within the hull grown by ``margin`` m. The
        growth is mitred at vertices and then cut to the hull's bounding box plus
        ``margin``, so it holds every point within ``margin`` of the hull (and a few
        near sharp corners farther out)."""
        v = self._points
        xc = origin_x + (np.arange(cols) + 0.5) * cell
        yc = origin_y + (np.arange(rows) + 0.5) * cell
        lo = np.full(rows, v[:, 0].min() - margin)
        hi = np.full(rows, v[:, 0].max() + margin)
        keep_rows = (yc >= v[:, 1].min() - margin) & (yc <= v[:, 1].max() + margin)
        if v.shape[0] >= 3:
            b = np.roll(v, -1, axis=0)
            ex, ey = (b - v).T
            length = np.hypot(ex, ey)
            # outward normal of a CCW edge: (ey, -ex) / length; n . p <= n . a + margin
            nx, ny = ey / length, -ex / length
            rhs = nx * v[:, 0] + ny * v[:, 1] + margin
            bound = rhs[None, :] - ny[None, :] * yc[:, None]  # nx * x <= bound
            with np.errstate(divide="ignore", invalid="ignore"):
                limit = bound / nx[None, :]
            right = nx > 1e-12
            left = nx < -1e-12
            level = ~(right | left)
            if right.any():
                hi = np.minimum(hi, limit[:, right].min(axis=1))
            if left.any():
                lo = np.maximum(lo, limit[:, left].max(axis=1))
            if level.any():  # horizontal edges: the row is in or out as a whole
                keep_rows &= (bound[:, level] >= 0.0).all(axis=1)
        inside: NDArray[np.bool_] = (
            keep_rows[:, None] & (xc[None, :] >= lo[:, None]) & (xc[None, :] <= hi[:, None])
        )
        return inside
