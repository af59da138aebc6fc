"""Progress checking and the recovery behaviours: plain decisions on plain numbers.

Units: m, s (sim time), rad; poses in odom. The ladder itself (which behaviour comes
next, when to give up) lives in :mod:`otonav.nav.navigation`; this module holds the
pieces it is built from.

* :class:`ProgressChecker`: "the distance to go along the path shrank by at least
  ``distance`` m within ``window`` s" (a robot creeping, dithering or oscillating
  fails it), plus "got ``distance`` m closer to the goal within ``goal_window`` s".
* :func:`follow_boundary`: Bug2-style wall following from the scan: keep the nearest
  return at ``distance`` m on the chosen side, drive along its tangent.
* :func:`boundary_side`: the side whose tangent heads closer to the goal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from otonav.nav.geometry import wrap_angle

__all__ = ("ProgressChecker", "boundary_side", "follow_boundary")


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
