"""The global planner (Nav2's planner server), no I/O: the map the scans build, what the
robot has observed (its hull; once the goal lies inside it, A* routes only within
``hull_margin`` of it, :mod:`otonav.nav._observed_hull`), the A* search on the map's
coarse grid over cells with at least the centre clearance, and when to run it: at once
for a new :class:`Plan`, then every ``replan_period`` s if the path ahead is blocked,
``expansions_per_tick`` cells a step. Before each search the cells the last scan saw
through are cleared (ADR 0026). Units: m, s of sim time; poses in odom.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from otonav.nav._costmap import ClearanceMap
from otonav.nav._global_path import AstarSearch, GridPath
from otonav.nav._observed_hull import ObservedHull, free_ends
from otonav.nav._plan_grid import best_points, free_threshold, pooled
from otonav.nav._scan import ScanRays
from otonav.params import NavigationParams

__all__ = ("LOOKAHEAD_TIME", "MIN_LOOKAHEAD", "GlobalPlanner", "Plan")

LOOKAHEAD_TIME = 2.0
"""s of the current speed the DWA's target lies ahead along the path (0.4 m/s: 0.8 m)."""

MIN_LOOKAHEAD = 0.4
"""m, the shortest lookahead (Nav2 Regulated Pure Pursuit's ``min_lookahead_dist``)."""

Pose = tuple[float, float, float]


@dataclass(slots=True)
class Plan:
    """One goal's path and the search for it (a new goal, or a replan from where a
    recovery left the robot: a new ``Plan``)."""

    goal: tuple[float, float]
    path: NDArray[np.float64] | None = None
    """(N, 2) m from the robot's position when planned to the goal; None: none yet."""
    length: float = math.nan
    """m along ``path``."""
    remaining: NDArray[np.float64] | None = None
    """m from each point of ``path`` to the goal along it."""
    search: AstarSearch | None = None
    """The search in progress (it goes on at the next step)."""
    checked_at: float = -math.inf
    replan_now: bool = True

    def follow(
        self, pose: Pose, distance: float, v0: float, lookahead: float
    ) -> tuple[float, tuple[float, float]]:
        """The distance to go, m (along the path from its point nearest the robot;
        ``distance`` without a path), and the DWA's target: the first path point at
        least the lookahead from the robot after that one (the goal when none). The
        lookahead scales with the speed, like Nav2's Regulated Pure Pursuit:
        ``LOOKAHEAD_TIME`` s of the current speed, within [``MIN_LOOKAHEAD``,
        ``lookahead``] m. A slow robot aims at the path near it: in a door at the
        passable limit it lines up on the path instead of heading for a point beyond
        the door past its corner (issue 24)."""
        path, remaining = self.path, self.remaining
        if path is None or remaining is None:
            return distance, self.goal
        d = np.hypot(path[:, 0] - pose[0], path[:, 1] - pose[1])
        i = int(d.argmin())  # (the array methods: no np.argmin/np.flatnonzero wrappers)
        lookahead = min(max(abs(v0) * LOOKAHEAD_TIME, MIN_LOOKAHEAD), lookahead)
        beyond = d[i:] >= lookahead
        j = i + int(beyond.argmax())  # the first True, or i when there is none
        target = (float(path[j, 0]), float(path[j, 1])) if beyond[j - i] else self.goal
        return float(d[i] + remaining[i]), target


class GlobalPlanner:
    """What outlives a goal (the map, the observed hull, the latest scan, counters), and
    the search that makes a :class:`Plan`'s path.

    Attributes:
        map: the obstacle map with per-cell clearance, around the start.
        hull: what the robot has observed: the search routes only within it.
        returns: the latest observed scan's returns, odom x and y (None before one).
        replans: searches started, over all goals.
        expansions: A* cells expanded, over all searches.
    """

    def __init__(self, params: NavigationParams, start: tuple[float, float]) -> None:
        p = params
        self.map = ClearanceMap(
            start[0],
            start[1],
            half_size=p.map_half_size,
            resolution=p.map_resolution,
            max_distance=max(p.dwa.radius + p.dwa.clearance_cap, p.follow_distance) + 0.05,
        )
        self.stride = max(1, round(p.plan_resolution / p.map_resolution))
        self.hull = ObservedHull(start[0], start[1])
        self.returns: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
        self.replans = 0
        self.expansions = 0
        self._rays: ScanRays | Callable[[], ScanRays] | None = None
        self._hull_mask: tuple[int, NDArray[np.bool_]] | None = None

    def observe(
        self,
        points_odom: NDArray[np.float64] | tuple[NDArray[np.float64], NDArray[np.float64]],
        rays: ScanRays | Callable[[], ScanRays] | None = None,
    ) -> int:
        """Record a scan's returns (odom: ``(N, 2)``, or x and y arrays); returns how
        many map cells were new. ``rays`` (the same scan as rays, or a function making
        them): kept, and used to clear what the scan saw through before the next
        search."""
        if isinstance(points_odom, tuple):
            self.returns = points_odom
        else:
            self.returns = (points_odom[:, 0], points_odom[:, 1])
        seen_x, seen_y = self.returns
        if rays is not None:
            seen = rays() if callable(rays) else rays
            self._rays = seen
            ex, ey = free_ends(seen)  # with the laser's position: one hull update a scan
            seen_x = np.concatenate((ex, (seen.x,), seen_x))
            seen_y = np.concatenate((ey, (seen.y,), seen_y))
        self.hull.add(seen_x, seen_y)
        return self.map.mark_xy(*self.returns)

    def update(self, plan: Plan, now: float, pose: Pose, p: NavigationParams) -> GridPath | None:
        """Start a search when one is due, advance the running one by at most
        ``expansions_per_tick`` cells; a finished search's result (its path, if any,
        is now ``plan.path``), or None."""
        due = now - plan.checked_at >= p.replan_period
        if due:
            plan.checked_at = now
        if plan.search is None and (
            plan.replan_now or (due and (plan.path is None or self._blocked(plan, pose, p)))
        ):
            self._start_search(plan, now, pose, p)
        search = plan.search
        if search is None:
            return None
        done = search.expansions
        result = search.advance(p.expansions_per_tick)
        self.expansions += search.expansions - done
        if result is not None:
            self._adopt(plan, result, pose)
        return result

    def _start_search(self, plan: Plan, now: float, pose: Pose, p: NavigationParams) -> None:
        plan.checked_at = now
        plan.replan_now = False
        self.replans += 1
        if self._rays is not None and p.clear_range > 0.0:
            rays = self._rays() if callable(self._rays) else self._rays
            self._rays = None  # one scan clears once
            self.map.clear_seen(rays, reach=p.clear_range, margin=2.0 * self.map.resolution)
        free, penalty = self._free_grid(plan.goal, p)
        plan.search = AstarSearch(
            free,
            penalty,
            self._coarse_cell(pose[0], pose[1]),
            self._coarse_cell(*plan.goal),
            max_expansions=p.max_expansions,
        )

    def _adopt(self, plan: Plan, result: GridPath, pose: Pose) -> None:
        """Take a finished search's path (none: ``plan.path`` is None)."""
        plan.search = None
        if not result.found:
            plan.path = None
            return
        cells = np.asarray(result.cells, dtype=np.intp)
        rows, cols = best_points(self.map.interior(), self.stride, cells[:, 0], cells[:, 1])
        res = self.map.resolution
        xy = np.empty((cells.shape[0], 2))
        xy[:, 0] = self.map.origin_x + (cols + 0.5) * res
        xy[:, 1] = self.map.origin_y + (rows + 0.5) * res
        xy[0] = pose[:2]
        xy[-1] = plan.goal
        plan.path = xy
        legs = np.hypot(*np.diff(xy, axis=0).T)
        plan.length = float(legs.sum())
        remaining = np.zeros(xy.shape[0])
        remaining[:-1] = np.cumsum(legs[::-1])[::-1]
        plan.remaining = remaining

    def _free_grid(
        self, goal: tuple[float, float], p: NavigationParams
    ) -> tuple[NDArray[np.bool_], NDArray[np.float32]]:
        # float32 like the map, np.minimum/np.maximum for np.clip: on the 200 x 200
        # grid the conversions were most of a replan's set-up.
        coarse = pooled(self.map.interior(), self.stride)
        radius = p.dwa.radius
        free = coarse >= np.float32(free_threshold(radius, self.map.resolution))
        free &= self._within_hull(goal, free.shape[0], p.hull_margin)
        room = p.dwa.clearance_cap
        gap = np.minimum(np.maximum(np.float32(radius + room) - coarse, 0.0), room)
        penalty = gap * np.float32(p.plan_penalty / room)
        return free, penalty

    def _within_hull(
        self, goal: tuple[float, float], n: int, margin: float
    ) -> NDArray[np.bool_] | bool:
        """The coarse cells within ``margin`` of what the robot has observed
        (:mod:`otonav.nav._observed_hull`), cached until the hull grows; True (no
        bound) while the goal lies outside it: the world evidently goes on beyond
        what was seen."""
        if not self.hull.contains(*goal):
            return True
        cached = self._hull_mask
        if cached is not None and cached[0] == self.hull.version:
            return cached[1]
        m = self.map
        mask = self.hull.mask(m.origin_x, m.origin_y, m.resolution * self.stride, n, n, margin)
        self._hull_mask = (self.hull.version, mask)
        return mask

    def _coarse_cell(self, x: float, y: float) -> tuple[int, int]:
        s, res = self.stride, self.map.resolution
        col = math.floor((x - self.map.origin_x) / (res * s))
        row = math.floor((y - self.map.origin_y) / (res * s))
        n = self.map.size // s
        return min(max(row, 0), n - 1), min(max(col, 0), n - 1)

    def _blocked(self, plan: Plan, pose: Pose, p: NavigationParams) -> bool:
        """The path ahead of the robot passes a cell under the centre clearance."""
        path = plan.path
        if path is None:
            return True
        d = np.hypot(path[:, 0] - pose[0], path[:, 1] - pose[1])
        ahead = path[int(np.argmin(d)) :]
        if ahead.shape[0] == 0:
            return False
        clear = self.map.clearance(ahead[:, 0], ahead[:, 1])
        if clear.size <= 1:
            return False
        return bool((clear[:-1] < free_threshold(p.dwa.radius, self.map.resolution)).any())
