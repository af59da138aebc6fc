"""Progress checking and the recovery behaviours: plain decisions on plain numbers.

Units: m, s (sim time), rad; poses in odom. The ladder itself (which behaviour comes
next, when to give up) lives in :mod:`otonav.nav.navigation`; this module holds the
pieces it is built from.

* :class:`ProgressChecker`: Nav2's "moved at least ``distance`` m within ``window`` s"
  (a robot dithering on the spot fails it), plus "got at least ``distance`` m closer
  to the goal than ever before within ``goal_window`` s" (a robot oscillating
  between two places fails that one).
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

    Attributes:
        distance: progress that counts, m (> 0).
        window: time allowed to move ``distance`` from the anchor, s (> 0).
        goal_window: time allowed to get ``distance`` closer to the goal than ever, s.
    """

    distance: float = 0.3
    window: float = 4.0
    goal_window: float = 15.0
    _anchor: tuple[float, float, float] | None = None
    _best: tuple[float, float] | None = None

    def reset(self) -> None:
        """Start over (after a recovery, or for a new goal)."""
        self._anchor = None
        self._best = None

    def update(self, now: float, x: float, y: float, goal_distance: float) -> str | None:
        if self._anchor is None or math.hypot(x - self._anchor[0], y - self._anchor[1]) >= (
            self.distance
        ):
            self._anchor = (now, x, y)
        if self._best is None or goal_distance <= self._best[1] - self.distance:
            self._best = (now, goal_distance)
        if now - self._anchor[0] >= self.window:
            return f"moved under {self.distance:g} m in {self.window:g} s"
        if now - self._best[0] >= self.goal_window:
            return f"no {self.distance:g} m closer to the goal in {self.goal_window:g} s"
        return None

    @property
    def anchor(self) -> tuple[float, float, float] | None:
        return self._anchor


def boundary_side(points: NDArray[np.float64], goal_bearing: float) -> int:
    """+1 to keep the obstacle on the left, -1 on the right: the side whose tangent at
    the nearest return (``points`` in base_link) points closer to ``goal_bearing``
    (rad, base_link). With no returns: the side the goal is not on."""
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
