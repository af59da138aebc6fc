"""Progress checking and the recovery ladder (Nav2's behaviours and the round-robin that
runs them), no I/O. Units: m, s (sim time), rad; poses in odom.

When progress fails (:class:`ProgressChecker`), the next stage of one goal's ladder
(:class:`Recovery`) runs: ``spin`` (turn ``spin_angle`` toward the goal side, the map
cleared within ``clear_radius`` first), ``backup`` (reverse ``backup_distance``),
``follow`` (:func:`follow_boundary` on the side that heads closer to the goal,
:func:`boundary_side`, Bug2-style, until ``progress_distance`` m closer to the goal than
where it started or ``follow_time`` s), then the ladder again (``round 2``, ...): only a
search that proved there is no path says ``unreachable`` (issue 42: the ladder alone
called 12 of 60 reachable BARN worlds unreachable). Real progress resets it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from otonav.nav._costmap import ClearanceMap
from otonav.nav._geometry import wrap_angle
from otonav.params import NavigationParams as Params

__all__ = (
    "LADDER",
    "TURN_CREDIT",
    "Points",
    "ProgressChecker",
    "Recovery",
    "Stage",
    "boundary_side",
    "follow_boundary",
)

Pose = tuple[float, float, float]
Points = NDArray[np.float64] | Callable[[], NDArray[np.float64]]
"""Scan returns in base_link, ``(N, 2)`` m, or a function that computes them."""

TURN_CREDIT = 0.4
"""m of progress per radian turned toward the target while it is more than the DWA's
``rotate_threshold`` off the heading (a half turn: (pi - 0.6) x 0.4 = 1.0 m). Nearer
than that the robot is meant to drive: turning does not count (issue 24: at a U
trap's outer corner the DWA turned ever slower toward a target through the wall, at
v = 0, and the credit for that turn kept the progress check quiet for 6 s)."""

LADDER = ("spin", "backup", "follow")
"""The recovery stages, in order."""


@dataclass(slots=True)
class ProgressChecker:
    """Is the robot getting anywhere? ``update`` returns the reason it is not, or None.

    Progress is judged on what the robot does, not on what the planner says (issue
    24): the robot's *distance to go* (along the current global path, or straight to
    the goal without one) must shrink by ``distance`` within ``window`` s. A robot
    creeping at near-zero speed, dithering on the spot or oscillating across the path
    fails it, whatever state the planner reports. Moving without getting nearer does
    not count (Nav2's radius check let an oscillating robot through until the goal
    window, 15 s, ran out).

    A new path (:meth:`rebase`) that is longer sets the reference to its distance to
    go, but not the clock: new knowledge of the world is not progress. Within
    ``goal_window`` s the robot must also get ``distance`` closer to the goal in a
    straight line (a backstop against paths that keep changing).

    Attributes:
        distance: progress that counts, m (> 0).
        window: time allowed to shrink the distance to go by ``distance``, s (> 0).
        goal_window: time allowed to get ``distance`` closer to the goal, s.
    """

    distance: float = 0.3
    window: float = 3.5
    goal_window: float = 30.0
    _best: tuple[float, float] | None = None
    _goal_best: tuple[float, float] | None = None

    def reset(self) -> None:
        """Start over (after a recovery, or for a new goal)."""
        self._best = None
        self._goal_best = None

    def rebase(self, to_go: float) -> None:
        """A new path whose distance to go is ``to_go``, m (the clock keeps running)."""
        if self._best is not None and to_go > self._best[1]:
            self._best = (self._best[0], to_go)

    def update(self, now: float, to_go: float, goal_distance: float) -> str | None:
        if self._best is None or to_go <= self._best[1] - self.distance:
            self._best = (now, to_go)
        if self._goal_best is None or goal_distance <= self._goal_best[1] - self.distance:
            self._goal_best = (now, goal_distance)
        if now - self._best[0] >= self.window:
            return f"under {self.distance:g} m of progress along the path in {self.window:g} s"
        if now - self._goal_best[0] >= self.goal_window:
            return f"no {self.distance:g} m closer to the goal in {self.goal_window:g} s"
        return None


def boundary_side(points: NDArray[np.float64], goal_bearing: float) -> int:
    """+1 to keep the obstacle on the left, -1 on the right: the side whose tangent at
    the nearest return (``points`` in base_link) points closer to ``goal_bearing``
    (rad, base_link). When both tangents are equally good (the nearest return dead
    ahead and the goal straight through it): +1, the obstacle on the left. With no
    returns: the side the goal is not on."""
    if points.shape[0] == 0:
        return -1 if goal_bearing >= 0.0 else 1
    i = int(np.argmin(np.hypot(points[:, 0], points[:, 1])))
    beta = math.atan2(points[i, 1], points[i, 0])
    left = abs(wrap_angle(beta - math.pi / 2 - goal_bearing))  # obstacle on the left
    right = abs(wrap_angle(beta + math.pi / 2 - goal_bearing))
    return 1 if left <= right else -1


def follow_boundary(
    points: NDArray[np.float64],
    side: int,
    *,
    distance: float,
    speed: float,
    max_omega: float,
    gain: float = 2.0,
) -> tuple[float, float]:
    """(v, omega) that drives along the nearest obstacle, keeping it ``distance`` m on
    ``side`` (+1 left, -1 right). With no returns: turn toward that side."""
    if points.shape[0] == 0:
        return speed, side * 0.5 * max_omega
    d = np.hypot(points[:, 0], points[:, 1])
    i = int(np.argmin(d))
    beta = math.atan2(points[i, 1], points[i, 0])
    # Tangent heading with the obstacle on ``side``, bent toward it when too far.
    error = wrap_angle(beta - side * math.pi / 2 + side * gain * (float(d[i]) - distance))
    omega = min(max(gain * error, -max_omega), max_omega)
    return speed * max(math.cos(error), 0.0), omega


def _resolve(points: Points) -> NDArray[np.float64]:
    return points() if callable(points) else points


@dataclass(slots=True)
class Stage:
    """A running stage of the ladder: its name, why, and when, where (odom pose) and how
    far from the goal (m) it began; ``side``: +1 turn or keep the obstacle left."""

    name: str
    why: str
    started: float
    pose: Pose
    goal_distance: float
    side: int


@dataclass(slots=True)
class Recovery:
    """One goal's recovery ladder (a new goal: a new ``Recovery``).

    Attributes:
        checker: the progress check.
        stage: the running stage, or None.
        gave_up: why the goal is unreachable (a search proved it), or None.
        looked_around: the ``spin`` after a first proof of no path has run.
        rung: the next rung (index into :data:`LADDER`).
        rounds: times the ladder started over without real progress, plus one.
        best: distance to the goal when the ladder last started over, m.
        to_go: distance to go along the path then (None: take the next one), m.
    """

    checker: ProgressChecker
    stage: Stage | None = None
    gave_up: str | None = None
    looked_around: bool = False
    rung: int = 0
    rounds: int = 1
    best: float = math.inf
    to_go: float | None = None

    def stuck(
        self, now: float, to_go: float, bearing: float, distance: float, new_path: bool, p: Params
    ) -> str | None:
        """Why the robot is not getting anywhere, or None. ``to_go``: along the path,
        m; ``bearing``: of the path's target off the heading, rad; ``new_path``: the
        plan just changed."""
        # Turning toward the way on counts too (a robot facing away from a new path
        # turns in place first): TURN_CREDIT m per radian of bearing to the target
        # beyond the DWA's rotate threshold (nearer, it should drive).
        measure = to_go + TURN_CREDIT * max(bearing - p.dwa.rotate_threshold, 0.0)
        if new_path:  # new knowledge is not progress, and not a lack of it
            self.checker.rebase(measure)
            if self.to_go is not None and to_go > self.to_go:
                self.to_go = to_go
        stuck = self.checker.update(now, measure, distance)
        if self.to_go is None:
            self.to_go = to_go
        # The ladder starts over after real progress: a progress distance closer to
        # the goal than where it began, or three along the path since the last rung.
        if distance <= self.best - p.progress_distance or (
            to_go <= self.to_go - 3.0 * p.progress_distance
        ):
            self.rung, self.best, self.to_go = 0, distance, to_go
        return stuck

    def next_rung(self, stuck: str) -> tuple[str, str]:
        """The next stage and why it runs. A path exists (no search proved otherwise):
        after the last rung the ladder starts over, from a fresh plan, until the budget
        ends (issue 42: false ``unreachable``)."""
        if self.rung >= len(LADDER):
            self.rung, self.rounds = 0, self.rounds + 1
        name = LADDER[self.rung]
        self.rung += 1
        again = f" (round {self.rounds})" if self.rounds > 1 else ""
        return name, f"rung {self.rung}/{len(LADDER)}{again}, {stuck}"

    def begin(
        self, stage: Stage, points: Points, heading: float, cmap: ClearanceMap, p: Params
    ) -> None:
        """Start ``stage`` (``heading``: the goal's bearing, rad, picks its side)."""
        if stage.name == "follow":
            stage.side = boundary_side(_resolve(points), heading)
        self.stage = stage
        if self.best == math.inf:
            self.best = stage.goal_distance
        if stage.name == "spin" and p.clear_radius > 0.0:
            # Nav2's first recovery: forget the map around the robot (a smeared wall,
            # a misread), and look around to see it again.
            cmap.clear_near(stage.pose[0], stage.pose[1], p.clear_radius)

    def command(
        self, now: float, pose: Pose, distance: float, points: Points, p: Params
    ) -> tuple[float, float, str, str] | None:
        """The running stage's (v, omega, "recovering", reason), or None when it is over
        (then: replan from here, and progress is judged afresh)."""
        st = self.stage
        assert st is not None
        elapsed = now - st.started
        v = omega = 0.0
        if st.name == "spin":
            turned = abs(wrap_angle(pose[2] - st.pose[2]))
            done = turned >= p.spin_angle - 0.05 or elapsed > p.spin_angle / p.spin_speed + 0.5
            omega = st.side * p.spin_speed
        elif st.name == "backup":
            moved = math.hypot(pose[0] - st.pose[0], pose[1] - st.pose[1])
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
            self.stage = None
            self.checker.reset()
            self.to_go = None
            return None
        return v, omega, "recovering", f"{st.name}: {st.why}"
