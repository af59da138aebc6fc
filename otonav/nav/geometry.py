"""Planar angle helpers. Angles in rad, CCW positive (ROS REP 103)."""

from __future__ import annotations

import math

__all__ = ("wrap_angle",)


def wrap_angle(a: float) -> float:
    """Wrap an angle into [-pi, pi], rad.

    Uses the IEEE remainder, which is exact: the result differs from ``a`` by an
    integer multiple of ``2*pi`` (as a float) and ``wrap_angle(wrap_angle(a)) ==
    wrap_angle(a)``. NaN and infinities give NaN.
    """
    return math.remainder(a, math.tau) if math.isfinite(a) else math.nan
