"""The avoiding navigator's logic: map, global path, DWA, progress and the recovery
ladder, in one deterministic object with no I/O (the actor feeds it and publishes).

Units: m, s of sim time, rad; poses in odom.

Each :meth:`Navigation.step` (at the navigator's rate):

1. no goal: ``idle``; within ``tolerance``: ``reached`` (latched until the robot is
   twice as far: settling must not restart the approach); after giving up:
   ``unreachable`` (until a new goal);
2. **global path** (:mod:`otonav.nav.global_path`) on the map's coarse grid, cells free
   when their clearance is at least the centre clearance and, once the goal lies inside
   what the robot has observed, within ``hull_margin`` of that
   (:mod:`otonav.nav.observed_hull`); replanned when there is none,
   every ``replan_period`` s if the path ahead is blocked, and after each recovery.
   Before each replan, the cells the last scan saw through are cleared (ADR 0026).
   No path, proven (the search exhausted every cell reachable from the goal): first
   look around (the ``spin`` stage), then, if still none, ``unreachable``: "no path
   to the goal in the observed map" (proven again after the look-around, on a map
   that kept only what the scans still show);
3. within ``approach_radius`` of the goal, a proportional controller finishes, forward
   or in reverse (an overshoot is backed out of, not turned around); farther away,
   **DWA** (:mod:`otonav.nav.dwa`) toward a point along the path (``LOOKAHEAD_TIME``
   s of the current speed ahead, within [``MIN_LOOKAHEAD``, ``lookahead``] m):
   ``driving``, or ``avoiding`` when the chosen arc passes near a return; ``blocked``
   when no arc is admissible;
4. **progress** (:class:`~otonav.nav.recovery.ProgressChecker`): when it fails, the next
   stage of the ladder runs (``recovering``): ``spin`` (turn ``spin_angle`` toward the
   goal side), ``backup`` (reverse ``backup_distance``), ``follow`` (follow the
   obstacle's boundary on the side that heads closer to the goal, Bug2-style, until
   ``distance`` m closer to the goal than where it started or ``follow_time`` s),
   then the ladder again (``round 2``, ...) from a fresh plan: only a search that
   proved there is no path says ``unreachable`` (issue 42: the ladder alone called 12
   of 60 reachable BARN worlds unreachable). Getting ``distance`` m closer to the goal
   than at the start of the ladder resets it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from otonav.nav.costmap import ClearanceMap
from otonav.nav.dwa import ClearanceFn, DwaResult, clear_arc, dwa_step
from otonav.nav.geometry import wrap_angle
from otonav.nav.global_path import AstarSearch, GridPath
from otonav.nav.local_clearance import local_clearance, nearby
from otonav.nav.observed_hull import ObservedHull, free_ends
from otonav.nav.plan_grid import best_points, free_threshold, pooled
from otonav.nav.recovery import ProgressChecker, boundary_side, follow_boundary
from otonav.nav.scan import ScanRays
from otonav.params import NavigationParams

__all__ = (
    "LADDER",
    "LOOKAHEAD_TIME",
    "MIN_LOOKAHEAD",
    "TURN_CREDIT",
    "NavOutput",
    "Navigation",
    "NavigationParams",
    "Points",
)

Points = NDArray[np.float64] | Callable[[], NDArray[np.float64]]
"""Scan returns in base_link, ``(N, 2)`` m, or a function that computes them."""


def _resolve(points: Points) -> NDArray[np.float64]:
    return points() if callable(points) else points


TURN_CREDIT = 0.4
"""m of progress per radian turned toward the target while it is more than the DWA's
``rotate_threshold`` off the heading (a half turn: (pi - 0.6) x 0.4 = 1.0 m). Nearer
than that the robot is meant to drive: turning does not count (issue 24: at a U
trap's outer corner the DWA turned ever slower toward a target through the wall, at
v = 0, and the credit for that turn kept the progress check quiet for 6 s)."""

LOOKAHEAD_TIME = 2.0
"""s of the current speed the DWA's target lies ahead along the path (0.4 m/s: 0.8 m)."""

MIN_LOOKAHEAD = 0.4
"""m, the shortest lookahead (Nav2 Regulated Pure Pursuit's ``min_lookahead_dist``)."""

LADDER = ("spin", "backup", "follow")
"""The recovery stages, in order."""


class NavOutput(NamedTuple):
    """One step's command and what explains it. A named tuple, immutable like a frozen
    dataclass but made in ~0.7 us instead of ~2.7 us (one per step)."""

    v: float
    omega: float
    state: str
    """idle | driving | avoiding | blocked | recovering | unreachable | reached."""
    reason: str
    distance: float
    heading_error: float
    dwa: DwaResult | None = None
    stage: str = ""
    path_length: float = math.nan
    replans: int = 0


@dataclass(slots=True)
class _Stage:
    name: str
    started: float
    x: float
    y: float
    yaw: float
    goal_distance: float
    side: int = 1
    why: str = ""


@dataclass(slots=True)
class Navigation:
    """The avoiding navigator's state (see the module docstring)."""

    params: NavigationParams
    start: tuple[float, float]
    goal: tuple[float, float] | None = None
    map: ClearanceMap = field(init=False)
    hull: ObservedHull = field(init=False)
    """What the robot has observed: the global planner routes only within it."""
    path: NDArray[np.float64] | None = None
    path_length: float = math.nan
    replans: int = 0
    _checker: ProgressChecker = field(init=False)
    _planned_at: float = -math.inf
    _checked_at: float = -math.inf
    _looked_around: bool = False
    _ladder: int = 0
    _rounds: int = 1
    _ladder_best: float = math.inf
    _ladder_to_go: float | None = None
    _remaining: NDArray[np.float64] | None = None
    _new_path: bool = False
    _stage: _Stage | None = None
    _gave_up: str | None = None
    _stride: int = field(init=False)
    _rays: ScanRays | Callable[[], ScanRays] | None = None
    _returns: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None
    _search: AstarSearch | None = None
    expansions: int = 0
    """A* cells expanded so far, over all searches."""
    _replan_now: bool = True
    _reached: bool = False
    _hull_mask: tuple[int, NDArray[np.bool_]] | None = None

    def __post_init__(self) -> None:
        p = self.params
        self.map = ClearanceMap(
            self.start[0],
            self.start[1],
            half_size=p.map_half_size,
            resolution=p.map_resolution,
            max_distance=max(p.dwa.radius + p.dwa.clearance_cap, p.follow_distance) + 0.05,
        )
        self._stride = max(1, round(p.plan_resolution / p.map_resolution))
        self.hull = ObservedHull(self.start[0], self.start[1])
        self._checker = ProgressChecker(
            p.progress_distance, p.progress_window, p.goal_progress_window
        )

    # -- inputs ------------------------------------------------------------------------

    def set_goal(self, goal: tuple[float, float]) -> None:
        if goal != self.goal:
            self.goal = goal
            self.path = None
            self._search = None
            self._replan_now = True
            self._gave_up = None
            self._reached = False
            self._stage = None
            self._ladder = 0
            self._rounds = 1
            self._ladder_best = math.inf
            self._ladder_to_go = None
            self._looked_around = False
            self._checker.reset()

    def observe(
        self,
        points_odom: NDArray[np.float64] | tuple[NDArray[np.float64], NDArray[np.float64]],
        rays: ScanRays | Callable[[], ScanRays] | None = None,
    ) -> int:
        """Record a scan's returns (odom: ``(N, 2)``, or x and y arrays); returns how
        many map cells were new. ``rays`` (the same scan as rays, or a function making
        them): kept, and used to clear what the scan saw through before the next
        replan."""
        if isinstance(points_odom, tuple):
            self._returns = points_odom
        else:
            self._returns = (points_odom[:, 0], points_odom[:, 1])
        seen_x, seen_y = self._returns
        if rays is not None:
            seen = rays() if callable(rays) else rays
            self._rays = seen
            ex, ey = free_ends(seen)  # with the laser's position: one hull update a scan
            seen_x = np.concatenate((ex, (seen.x,), seen_x))
            seen_y = np.concatenate((ey, (seen.y,), seen_y))
        self.hull.add(seen_x, seen_y)
        return self.map.mark_xy(*self._returns)

    @property
    def searching(self) -> bool:
        """A global search is in progress (it goes on at the next step)."""
        return self._search is not None

    # -- the step ----------------------------------------------------------------------

    def step(
        self,
        now: float,
        pose: tuple[float, float, float],
        v0: float,
        omega0: float,
        points: Points,
    ) -> NavOutput:
        """One decision. ``points``: the latest scan's returns in the current
        base_link, or a function that computes them (only boundary following needs
        them, so the caller's transform is skipped otherwise)."""
        if self.goal is None:
            return NavOutput(0.0, 0.0, "idle", "no goal", math.inf, 0.0)
        x, y, yaw = pose
        gx, gy = self.goal
        distance = math.hypot(gx - x, gy - y)
        heading = wrap_angle(math.atan2(gy - y, gx - x) - yaw)
        if self._gave_up is not None:
            return self._out(0.0, 0.0, "unreachable", self._gave_up, distance, heading)
        # Reached latches (Nav2's stateful goal checker): a robot settling or drifting a
        # few mm back out of the tolerance stays arrived, until pushed twice as far.
        tolerance = self.params.tolerance
        if distance <= tolerance or (self._reached and distance <= 2.0 * tolerance):
            self._stage = None
            self._reached = True
            return self._out(0.0, 0.0, "reached", "within tolerance", distance, heading)
        self._reached = False
        if self._stage is not None:
            out = self._recover(now, pose, distance, heading, points)
            if out is not None:
                return out
        due = now - self._checked_at >= self.params.replan_period
        if due:
            self._checked_at = now
        if self._search is None and (
            self._replan_now or (due and (self.path is None or self._path_blocked(pose)))
        ):
            self._start_search(now, pose)
        if self._search is not None:
            search = self._search
            done = search.expansions
            planned = search.advance(self.params.expansions_per_tick)
            self.expansions += search.expansions - done
            proven_none = planned is not None and self._adopt(planned, pose)
            if proven_none:
                if not self._looked_around:
                    self._looked_around = True
                    return self._begin(
                        "spin", now, pose, distance, heading, points, "look-around, no path"
                    )
                return self._give_up("no path to the goal in the observed map", distance, heading)
        to_go = self._to_go(pose, distance)
        target = self._target(pose, v0)
        # Turning toward the way on counts too (a robot facing away from a new path
        # turns in place first): TURN_CREDIT m per radian of bearing to the target
        # beyond the DWA's rotate threshold (nearer, it should drive).
        bearing = abs(wrap_angle(math.atan2(target[1] - y, target[0] - x) - yaw))
        measure = to_go + TURN_CREDIT * max(bearing - self.params.dwa.rotate_threshold, 0.0)
        if self._new_path:  # new knowledge is not progress, and not a lack of it
            self._new_path = False
            self._checker.rebase(measure)
            if self._ladder_to_go is not None and to_go > self._ladder_to_go:
                self._ladder_to_go = to_go
        stuck = self._checker.update(now, measure, distance)
        if self._ladder_to_go is None:
            self._ladder_to_go = to_go
        # The ladder starts over after real progress: a progress distance closer to
        # the goal than where it began, or three along the path since the last rung.
        if distance <= self._ladder_best - self.params.progress_distance or (
            to_go <= self._ladder_to_go - 3.0 * self.params.progress_distance
        ):
            self._ladder, self._ladder_best, self._ladder_to_go = 0, distance, to_go
        if stuck is not None and not (self._search is not None and self.path is None):
            # (while the first search for a path is still running, the robot heads for
            # the goal and the verdict waits for it: at most max_expansions /
            # expansions_per_tick steps)
            if self._ladder >= len(LADDER):
                # A path exists (no search proved otherwise): the goal is not
                # unreachable, however stuck the robot is. The ladder starts over from
                # a fresh plan until the budget ends (issue 42: false `unreachable`).
                self._ladder, self._rounds = 0, self._rounds + 1
            stage = LADDER[self._ladder]
            self._ladder += 1
            again = f" (round {self._rounds})" if self._rounds > 1 else ""
            why = f"rung {self._ladder}/{len(LADDER)}{again}, {stuck}"
            return self._begin(stage, now, pose, distance, heading, points, why)
        if distance < self.params.approach_radius:
            return self._approach(distance, heading)
        dwa = self.params.dwa
        result = (
            clear_arc(pose, v0, omega0, target, distance, self.map.clearance_at, dwa)
            if dwa.fast_path
            else None
        ) or dwa_step(pose, v0, omega0, target, distance, self._local_clearance(pose), dwa)
        if result.admissible == 0:
            state = "blocked"
        else:
            state = "avoiding" if result.reason == "avoiding" else "driving"
        return self._out(result.v, result.omega, state, result.reason, distance, heading, result)

    # -- pieces ------------------------------------------------------------------------

    def _out(
        self,
        v: float,
        omega: float,
        state: str,
        reason: str,
        distance: float,
        heading: float,
        dwa: DwaResult | None = None,
    ) -> NavOutput:
        return NavOutput(
            v,
            omega,
            state,
            reason,
            distance,
            heading,
            dwa,
            self._stage.name if self._stage is not None else "",
            self.path_length if self.path is not None else math.nan,
            self.replans,
        )

    def _approach(self, distance: float, heading: float) -> NavOutput:
        """The last centimetres: P-control on distance and heading, in reverse when the
        goal is behind (an overshoot is undone by backing up, not by a U-turn); the
        safety layer still checks every command."""
        p = self.params
        ahead = abs(heading) <= math.pi / 2
        facing = heading if ahead else wrap_angle(heading - math.pi)
        v_max = min(p.dwa.max_v, math.sqrt(p.dwa.max_accel * distance))
        v = min(p.kp_lin * distance, v_max) * math.cos(facing) * (1.0 if ahead else -1.0)
        omega = min(max(p.kp_ang * facing, -p.dwa.max_omega), p.dwa.max_omega)
        return self._out(v, omega, "driving", "final approach", distance, heading)

    def _give_up(self, reason: str, distance: float, heading: float) -> NavOutput:
        self._gave_up = reason
        self._stage = None
        return self._out(0.0, 0.0, "unreachable", reason, distance, heading)

    def _local_clearance(self, pose: tuple[float, float, float]) -> ClearanceFn:
        """The DWA's distances: exact to the latest scan's returns near the robot, the
        map's elsewhere (:mod:`otonav.nav.local_clearance`)."""
        dwa = self.params.dwa
        if self._returns is None:
            return self.map.clearance
        reach = dwa.max_v * dwa.horizon + dwa.radius + 0.1
        rx, ry = nearby(*self._returns, pose[0], pose[1], reach)
        return local_clearance(self.map.clearance, self.map.slack, dwa.radius, rx, ry)

    def _free_grid(self) -> tuple[NDArray[np.bool_], NDArray[np.float32]]:
        # float32 like the map, np.minimum/np.maximum for np.clip: on the 200 x 200
        # grid the conversions were most of a replan's set-up.
        coarse = pooled(self.map.interior(), self._stride)
        radius = self.params.dwa.radius
        free = coarse >= np.float32(free_threshold(radius, self.map.resolution))
        free &= self._within_hull(free.shape[0])
        room = self.params.dwa.clearance_cap
        gap = np.minimum(np.maximum(np.float32(radius + room) - coarse, 0.0), room)
        penalty = gap * np.float32(self.params.plan_penalty / room)
        return free, penalty

    def _within_hull(self, n: int) -> NDArray[np.bool_] | bool:
        """The coarse cells within ``hull_margin`` of what the robot has observed
        (:mod:`otonav.nav.observed_hull`), cached until the hull grows; True (no
        bound) while the goal lies outside it: the world evidently goes on beyond
        what was seen."""
        assert self.goal is not None
        if not self.hull.contains(*self.goal):
            return True
        cached = self._hull_mask
        if cached is not None and cached[0] == self.hull.version:
            return cached[1]
        m = self.map
        mask = self.hull.mask(
            m.origin_x, m.origin_y, m.resolution * self._stride, n, n, self.params.hull_margin
        )
        self._hull_mask = (self.hull.version, mask)
        return mask

    def _coarse_cell(self, x: float, y: float) -> tuple[int, int]:
        s, res = self._stride, self.map.resolution
        col = math.floor((x - self.map.origin_x) / (res * s))
        row = math.floor((y - self.map.origin_y) / (res * s))
        n = self.map.size // s
        return min(max(row, 0), n - 1), min(max(col, 0), n - 1)

    def _start_search(self, now: float, pose: tuple[float, float, float]) -> None:
        """Begin a replan (it may take several steps: :meth:`step` advances it)."""
        assert self.goal is not None
        self._planned_at = self._checked_at = now
        self._replan_now = False
        self.replans += 1
        if self._rays is not None and self.params.clear_range > 0.0:
            rays = self._rays() if callable(self._rays) else self._rays
            self._rays = None  # one scan clears once
            self.map.clear_seen(
                rays, reach=self.params.clear_range, margin=2.0 * self.map.resolution
            )
        free, penalty = self._free_grid()
        self._search = AstarSearch(
            free,
            penalty,
            self._coarse_cell(pose[0], pose[1]),
            self._coarse_cell(*self.goal),
            max_expansions=self.params.max_expansions,
        )

    def _adopt(self, result: GridPath, pose: tuple[float, float, float]) -> bool:
        """Take a finished search's path; True when it proved there is none."""
        assert self.goal is not None
        self._search = None
        if not result.found:
            self.path = None
            return result.exhausted
        cells = np.asarray(result.cells, dtype=np.intp)
        rows, cols = best_points(self.map.interior(), self._stride, cells[:, 0], cells[:, 1])
        res = self.map.resolution
        xy = np.empty((cells.shape[0], 2))
        xy[:, 0] = self.map.origin_x + (cols + 0.5) * res
        xy[:, 1] = self.map.origin_y + (rows + 0.5) * res
        xy[0] = pose[:2]
        xy[-1] = self.goal
        self.path = xy
        legs = np.hypot(*np.diff(xy, axis=0).T)
        self.path_length = float(legs.sum())
        remaining = np.zeros(xy.shape[0])
        remaining[:-1] = np.cumsum(legs[::-1])[::-1]
        self._remaining = remaining
        self._new_path = True
        return False

    def _to_go(self, pose: tuple[float, float, float], distance: float) -> float:
        """Distance to go, m: along the path from its point nearest the robot, or
        straight to the goal without a path."""
        path, remaining = self.path, self._remaining
        if path is None or remaining is None:
            return distance
        d = np.hypot(path[:, 0] - pose[0], path[:, 1] - pose[1])
        i = int(d.argmin())
        return float(d[i] + remaining[i])

    def _path_blocked(self, pose: tuple[float, float, float]) -> bool:
        if self.path is None:
            return True
        ahead = self._ahead(pose)
        if ahead.shape[0] == 0:
            return False
        clear = self.map.clearance(ahead[:, 0], ahead[:, 1])
        if clear.size <= 1:
            return False
        limit = free_threshold(self.params.dwa.radius, self.map.resolution)
        return bool((clear[:-1] < limit).any())

    def _ahead(self, pose: tuple[float, float, float]) -> NDArray[np.float64]:
        assert self.path is not None
        d = np.hypot(self.path[:, 0] - pose[0], self.path[:, 1] - pose[1])
        return self.path[int(np.argmin(d)) :]

    def _target(self, pose: tuple[float, float, float], v0: float) -> tuple[float, float]:
        """The first path point at least the lookahead from the robot, after the one
        nearest it (one distance pass serves both searches). The lookahead scales with
        the speed, like Nav2's Regulated Pure Pursuit: ``LOOKAHEAD_TIME`` s of the
        current speed, within [``MIN_LOOKAHEAD``, ``lookahead``] m. A slow robot aims
        at the path near it: in a door at the passable limit it lines up on the path
        instead of heading for a point beyond the door past its corner (issue 24)."""
        assert self.goal is not None
        path = self.path
        if path is None:
            return self.goal
        d = np.hypot(path[:, 0] - pose[0], path[:, 1] - pose[1])
        i = int(d.argmin())  # (the array methods: no np.argmin/np.flatnonzero wrappers)
        lookahead = min(max(abs(v0) * LOOKAHEAD_TIME, MIN_LOOKAHEAD), self.params.lookahead)
        beyond = d[i:] >= lookahead
        j = i + int(beyond.argmax())  # the first True, or i when there is none
        if not beyond[j - i]:
            return self.goal
        return float(path[j, 0]), float(path[j, 1])

    def _begin(
        self,
        name: str,
        now: float,
        pose: tuple[float, float, float],
        distance: float,
        heading: float,
        points: Points,
        why: str,
    ) -> NavOutput:
        if name == "follow":
            side = boundary_side(_resolve(points), heading)
        else:
            side = 1 if heading >= 0 else -1
        self._stage = _Stage(name, now, pose[0], pose[1], pose[2], distance, side, why)
        if self._ladder_best == math.inf:
            self._ladder_best = distance
        if name == "spin" and self.params.clear_radius > 0.0:
            # Nav2's first recovery: forget the map around the robot (a smeared wall,
            # a misread), and look around to see it again.
            self.map.clear_near(pose[0], pose[1], self.params.clear_radius)
        out = self._recover(now, pose, distance, heading, points)
        assert out is not None
        return out

    def _recover(
        self,
        now: float,
        pose: tuple[float, float, float],
        distance: float,
        heading: float,
        points: Points,
    ) -> NavOutput | None:
        """The current stage's command, or None when it is over (then replan, drive)."""
        st, p = self._stage, self.params
        assert st is not None
        elapsed = now - st.started
        done = False
        v = omega = 0.0
        if st.name == "spin":
            turned = abs(wrap_angle(pose[2] - st.yaw))
            done = turned >= p.spin_angle - 0.05 or elapsed > p.spin_angle / p.spin_speed + 0.5
            omega = st.side * p.spin_speed
        elif st.name == "backup":
            moved = math.hypot(pose[0] - st.x, pose[1] - st.y)
            done = moved >= p.backup_distance or elapsed > p.backup_distance / p.backup_speed + 0.5
            v = -p.backup_speed
        else:
            done = elapsed > p.follow_time or distance <= st.goal_distance - p.progress_distance
            v, omega = follow_boundary(
                _resolve(points),
                st.side,
                distance=p.follow_distance,
                speed=p.follow_speed,
                max_omega=p.dwa.max_omega,
            )
        if done:
            self._stage = None
            self._checker.reset()
            self.path = None  # replan from here
            self._search = None
            self._replan_now = True
            self._ladder_to_go = None
            return None
        return self._out(v, omega, "recovering", f"{st.name}: {st.why}", distance, heading)
