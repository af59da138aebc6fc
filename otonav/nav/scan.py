"""Laser scan to points: returns in base_link, and frame changes on the plane.

Scan convention follows ``sensor_msgs/LaserScan`` (REP 103, REP 117): beam ``i`` points
at ``angle_min + i*angle_increment`` rad CCW from the laser's x axis; a valid return is
finite and within ``[range_min, range_max]``; ``+inf`` means nothing within range;
``-inf`` means an object closer than ``range_min``. The laser frame is
``laser_offset_x`` m ahead of base_link, unrotated (``RobotGeometry``).

A beam reporting ``-inf``, or a finite value below ``range_min``, is *blocked*: there is
something within ``range_min`` of the laser in that direction but not where. Such a
beam becomes a point at ``range_min / 2`` along it (the middle of where the object can
be), and :attr:`ScanPoints.blocked` says it happened. NaN is ignored.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ("ScanPoints", "scan_points", "to_frame")

Points = NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class ScanPoints:
    """The returns of one scan in base_link, m: an ``(N, 2)`` array (x forward, y left).

    Attributes:
        xy: valid returns plus one point per blocked beam, base_link, m.
        blocked: some beam reported a return closer than ``range_min``.
    """

    xy: Points
    blocked: bool


@lru_cache(maxsize=8)
def _directions(n: int, angle_min: float, angle_increment: float) -> tuple[Points, Points]:
    angles = angle_min + angle_increment * np.arange(n, dtype=np.float64)
    c, s = np.cos(angles), np.sin(angles)
    c.flags.writeable = False
    s.flags.writeable = False
    return c, s


def scan_points(
    ranges: NDArray[np.floating[Any]],
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
    laser_offset_x: float,
) -> ScanPoints:
    """The scan's returns as points in base_link (see the module docstring).

    Raises:
        ValueError: if ``ranges`` is not 1-D or an angle is not finite.
    """
    if ranges.ndim != 1:
        raise ValueError(f"ranges must be 1-D, got shape {ranges.shape}")
    if not (math.isfinite(angle_min) and math.isfinite(angle_increment)):
        raise ValueError(f"scan angles must be finite, got {angle_min!r}, {angle_increment!r}")
    c, s = _directions(ranges.shape[0], float(angle_min), float(angle_increment))
    r = np.asarray(ranges, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        valid = (r >= range_min) & (r <= range_max)  # NaN and +-inf compare False
        near = (r < range_min) & ~np.isnan(r)  # -inf and finite values under range_min
    blocked = bool(near.any())
    if blocked:
        valid = valid | near
        r = np.where(near, 0.5 * range_min, r)
    rv = r[valid]
    xy = np.empty((rv.shape[0], 2))
    xy[:, 0] = laser_offset_x + rv * c[valid]
    xy[:, 1] = rv * s[valid]
    return ScanPoints(xy, blocked)


def to_frame(
    xy: Points,
    from_pose: tuple[float, float, float],
    to_pose: tuple[float, float, float] | None = None,
) -> Points:
    """Points given in the body frame at ``from_pose`` (x, y, yaw in odom), expressed
    in odom, or, with ``to_pose``, in the body frame at ``to_pose``."""
    x, y, yaw = from_pose
    c, s = math.cos(yaw), math.sin(yaw)
    ox = x + c * xy[:, 0] - s * xy[:, 1]
    oy = y + s * xy[:, 0] + c * xy[:, 1]
    if to_pose is None:
        return np.stack((ox, oy), axis=1)
    tx, ty, tyaw = to_pose
    dx, dy = ox - tx, oy - ty
    ct, st = math.cos(tyaw), math.sin(tyaw)
    return np.stack((ct * dx + st * dy, -st * dx + ct * dy), axis=1)
