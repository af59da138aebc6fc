"""One scan, one conversion: the navigator and the safety layer receive the same
LaserScan object (messages are shared, never copied), so what they compute from it
(its ranges as an array, its points in base_link) is computed once and reused by
whoever asks second. Both ask only when they need it (the navigator when the robot
moved, the safety layer when a return may be within reach); the nearest return's
distance has its own cheaper functions."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from otonav.msgs import LaserScan
from otonav.nav._scan import ScanPoints, ScanRays, nearest_return, scan_in_frame, scan_points

Wire = tuple[NDArray[np.float64], float, float, float, float]

_last: tuple[LaserScan, float, ScanPoints] | None = None
_last_wire: tuple[LaserScan, Wire] | None = None


def points_of(scan: LaserScan, laser_offset_x: float) -> ScanPoints:
    """The scan's returns in base_link (:func:`otonav.nav._scan.scan_points`)."""
    global _last
    if _last is not None and _last[0] is scan and _last[1] == laser_offset_x:
        return _last[2]
    seen = scan_points(*_wire(scan), laser_offset_x)
    _last = (scan, laser_offset_x, seen)
    return seen


def odom_xy_of(
    scan: LaserScan, laser_offset_x: float, pose: tuple[float, float, float]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The scan's returns in odom at the body pose ``pose``, as x and y arrays
    (:func:`otonav.nav._scan.scan_in_frame`: the floats of ``to_frame(points_of(...))``
    with ~6 fewer numpy calls and no (N, 2) arrays)."""
    return scan_in_frame(*_wire(scan), laser_offset_x, pose)


def nearest_of(scan: LaserScan, laser_offset_x: float) -> float:
    """Base_link origin to the scan's nearest return, m (:func:`nearest_return`)."""
    return nearest_return(*_wire(scan), laser_offset_x)


def nearest_bound_of(scan: LaserScan, laser_offset_x: float) -> float:
    """A lower bound on :func:`nearest_of`, m, for ~1/6 of its cost: the shortest
    valid range less the laser's offset (a return ``r`` from the laser is at least
    ``r - |offset|`` from base_link). With a blocked beam (a range under
    ``range_min``) it is :func:`nearest_of` itself; NaN beams are ignored, as there."""
    ranges, _, _, range_min, _ = _wire(scan)
    if ranges.shape[0] == 0:
        return math.inf
    shortest = float(np.fmin.reduce(ranges))  # NaN only when every beam is NaN
    if math.isnan(shortest):
        return math.inf
    if shortest < range_min:
        return nearest_of(scan, laser_offset_x)
    return shortest - abs(laser_offset_x)


def _wire(scan: LaserScan) -> Wire:
    """Ranges, angle_min, angle_increment, range_min, range_max as the pure functions
    take them (cached for the last scan: a tuple of 360 floats to an array is ~5 us).
    The angles and limits are float32 on the wire (ROS 2): used as float32 here too,
    so a replay from the recording computes the same points."""
    global _last_wire
    if _last_wire is not None and _last_wire[0] is scan:
        return _last_wire[1]
    f32 = np.float32
    ranges = np.asarray(scan.ranges, dtype=np.float64)
    ranges.flags.writeable = False  # shared by every caller
    wire = (
        ranges,
        float(f32(scan.angle_min)),
        float(f32(scan.angle_increment)),
        float(f32(scan.range_min)),
        float(f32(scan.range_max)),
    )
    _last_wire = (scan, wire)
    return wire


def rays_of(scan: LaserScan, laser_offset_x: float, pose: tuple[float, float, float]) -> ScanRays:
    """The scan as rays in odom, taken at the body pose ``pose`` (x, y, yaw)."""
    x, y, yaw = pose
    ranges, angle_min, angle_increment, range_min, range_max = _wire(scan)
    return ScanRays(
        x + laser_offset_x * math.cos(yaw),
        y + laser_offset_x * math.sin(yaw),
        yaw,
        ranges,
        angle_min,
        angle_increment,
        range_min,
        range_max,
    )
