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

__all__ = ("ScanPoints", "ScanRays", "nearest_return", "scan_in_frame", "scan_points", "to_frame")

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


@dataclass(frozen=True, slots=True)
class ScanRays:
    """One scan as rays in odom, for clearing what it saw through.

    Attributes:
        x, y, yaw: the laser's pose in odom when the scan was taken (m, m, rad).
        ranges: the beams' ranges as in ``LaserScan`` (float64).
        angle_min: beam 0's angle from the laser's x axis, rad.
        angle_increment: rad between beams.
        range_min, range_max: the valid range, m.
    """

    x: float
    y: float
    yaw: float
    ranges: Points
    angle_min: float
    angle_increment: float
    range_min: float
    range_max: float

    def seen_free(self) -> Points:
        """Per beam, how far the beam is known empty, m: the range of a valid return,
        ``range_max`` for ``+inf`` (nothing within range), 0 for NaN and for a blocked
        beam; each the least of the beam and its two neighbours (a cell between two
        beams is only as free as the shorter one says)."""
        r = self.ranges
        free = np.where((r >= self.range_min) & (r <= self.range_max), r, 0.0)
        free = np.where(r == np.inf, self.range_max, free)
        return np.minimum(np.minimum(free, np.roll(free, 1)), np.roll(free, -1))


@lru_cache(maxsize=8)
def _directions(n: int, angle_min: float, angle_increment: float) -> tuple[Points, Points]:
    angles = angle_min + angle_increment * np.arange(n, dtype=np.float64)
    c, s = np.cos(angles), np.sin(angles)
    c.flags.writeable = False
    s.flags.writeable = False
    return c, s


def _returns(
    ranges: NDArray[np.floating[Any]],
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
) -> tuple[Points, Points, Points, bool]:
    """The ranges of the returns (blocked beams at ``range_min / 2``), their beams'
    cosines and sines, and whether a beam was blocked. A value up to ``range_max`` is
    a return or a blocked beam (NaN compares False); with no beam under ``range_min``
    (one NaN-ignoring minimum tells) that is the whole test: 5 numpy calls, not 9."""
    if ranges.ndim != 1:
        raise ValueError(f"ranges must be 1-D, got shape {ranges.shape}")
    if not (math.isfinite(angle_min) and math.isfinite(angle_increment)):
        raise ValueError(f"scan angles must be finite, got {angle_min!r}, {angle_increment!r}")
    c, s = _directions(ranges.shape[0], float(angle_min), float(angle_increment))
    r = np.asarray(ranges, dtype=np.float64)
    blocked = r.shape[0] > 0 and bool(np.fmin.reduce(r) < range_min)  # -inf included
    valid = r <= range_max
    if blocked:
        r = np.where(r < range_min, 0.5 * range_min, r)
    return r[valid], c[valid], s[valid], blocked


def scan_points(
    ranges: NDArray[np.floating[Any]],
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
    laser_offset_x: float,
) -> ScanPoints:
    """The scan's returns as points in base_link (module docstring); ValueError if
    ``ranges`` is not 1-D or an angle is not finite."""
    rv, cv, sv, blocked = _returns(ranges, angle_min, angle_increment, range_min, range_max)
    xy = np.empty((rv.shape[0], 2))
    xy[:, 0] = laser_offset_x + rv * cv
    xy[:, 1] = rv * sv
    return ScanPoints(xy, blocked)


def scan_in_frame(
    ranges: NDArray[np.floating[Any]],
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
    laser_offset_x: float,
    pose: tuple[float, float, float],
) -> tuple[Points, Points]:
    """The returns of :func:`scan_points` taken at the body pose ``pose`` (x, y, yaw)
    in odom, as x and y arrays: the same floats as ``to_frame(scan_points(...).xy,
    pose)`` without the (N, 2) arrays in between (the navigator's map update needs the
    coordinates, not the points). Raises as :func:`scan_points`."""
    rv, cv, sv, _ = _returns(ranges, angle_min, angle_increment, range_min, range_max)
    px = laser_offset_x + rv * cv
    py = rv * sv
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    return x + c * px - s * py, y + s * px + c * py


@lru_cache(maxsize=8)
def _offset_terms(n: int, angle_min: float, angle_increment: float, offset: float) -> Points:
    c, _ = _directions(n, angle_min, angle_increment)
    terms = 2.0 * offset * c
    terms.flags.writeable = False
    return terms


def nearest_return(
    ranges: NDArray[np.floating[Any]],
    angle_min: float,
    angle_increment: float,
    range_min: float,
    range_max: float,
    laser_offset_x: float,
) -> float:
    """Distance, m, from base_link's origin to the nearest point :func:`scan_points`
    returns for the same scan (inf with none), without making the points: with the
    laser ``o`` ahead, a return ``r`` along ``a`` is ``sqrt(r**2 + 2 o r cos a + o**2)``
    away. A third of the numpy calls of the points and their norms (the safety
    layer's fast-path test runs on every scan)."""
    if ranges.ndim != 1:
        raise ValueError(f"ranges must be 1-D, got shape {ranges.shape}")
    r = np.asarray(ranges, dtype=np.float64)
    near = r < range_min  # -inf and finite values under range_min; NaN is not
    if near.any():  # a blocked beam is a point at range_min / 2 along it
        r = np.where(near, 0.5 * range_min, r)
        range_min = 0.5 * range_min
    rv = np.where((r >= range_min) & (r <= range_max), r, np.inf)
    terms = _offset_terms(r.shape[0], float(angle_min), float(angle_increment), laser_offset_x)
    least = float((rv * (rv + terms)).min())  # inf * (inf + finite) stays inf
    if not math.isfinite(least):
        return math.inf
    return math.sqrt(max(least + laser_offset_x * laser_offset_x, 0.0))


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
