"""Planar angle helpers. Angles in rad, CCW positive (ROS REP 103)."""

from __future__ import annotations

import math

from otonav.limits import MAX_COORDINATE_M

__all__ = ("goal_problem", "wrap_angle")


def wrap_angle(a: float) -> float:
    """Wrap an angle into [-pi, pi], rad.

    Uses the IEEE remainder, which is exact: the result differs from ``a`` by an
    integer multiple of ``2*pi`` (as a float) and ``wrap_angle(wrap_angle(a)) ==
    wrap_angle(a)``. NaN and infinities give NaN.
    """
    return math.remainder(a, math.tau) if math.isfinite(a) else math.nan


def goal_problem(x: float, y: float) -> str | None:
    """Why a goal at (``x``, ``y``) cannot be driven to, or None: each coordinate must be a
    finite number within the world a scenario can describe (``|x|, |y| <=``
    :data:`~otonav.limits.MAX_COORDINATE_M`, the bound of a scenario's goal). A goal at
    x = NaN, inf or 1e308 crashed the navigator's map lookup (issue 41)."""
    for axis, value in (("x", x), ("y", y)):
        if not (isinstance(value, int | float) and abs(value) <= MAX_COORDINATE_M):
            return (
                f"goal {axis} = {value!r}: must be a finite number of metres within "
                f"[{-MAX_COORDINATE_M:g}, {MAX_COORDINATE_M:g}]"
            )
    return None
