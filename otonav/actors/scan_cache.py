"""One scan, one conversion: the navigator and the safety layer receive the same
LaserScan object (messages are shared, never copied), so its points in base_link are
computed once and reused by whoever asks second. Both ask only when they need the
points (the navigator when the robot moved, the safety layer when a return is within
reach); the nearest return's distance has its own cheaper function."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from otonav.msgs import LaserScan
from otonav.nav.scan import ScanPoints, ScanRays, nearest_return, scan_points

_last: tuple[LaserScan, float, ScanPoints] | None = None


def points_of(scan: LaserScan, laser_offset_x: float) -> ScanPoints:
    """The scan's returns in base_link (:func:`otonav.nav.scan.scan_points`)."""
    global _last
    if _last is not None and _last[0] is scan and _last[1] == laser_offset_x:
        return _last[2]
    seen = scan_points(*_wire(scan), laser_offset_x)
    _last = (scan, laser_offset_x, seen)
    return seen


def nearest_of(scan: LaserScan, laser_offset_x: float) -> float:
    """Base_link origin to the scan's nearest return, m (:func:`nearest_return`)."""
    return nearest_return(*_wire(scan), laser_offset_x)


def _wire(scan: LaserScan) -> tuple[NDArray[np.float64], float, float, float, float]:
    """Ranges, angle_min, angle_increment, range_min, range_max as the pure functions
    take them. The angles and limits are float32 on the wire (ROS 2): used as float32
    here too, so a replay from the recording computes the same points."""
    f32 = np.float32
    return (
        np.asarray(scan.ranges, dtype=np.float64),
        float(f32(scan.angle_min)),
        float(f32(scan.angle_increment)),
        float(f32(scan.range_min)),
        float(f32(scan.range_max)),
    )


def rays_of(scan: LaserScan, laser_offset_x: float, pose: tuple[float, float, float]) -> ScanRays:
    """The scan as rays in odom, taken at the body pose ``pose`` (x, y, yaw)."""
    f32 = np.float32
    x, y, yaw = pose
    return ScanRays(
        x + laser_offset_x * math.cos(yaw),
        y + laser_offset_x * math.sin(yaw),
        yaw,
        np.asarray(scan.ranges, dtype=np.float64),
        float(f32(scan.angle_min)),
        float(f32(scan.angle_increment)),
        float(f32(scan.range_min)),
        float(f32(scan.range_max)),
    )
