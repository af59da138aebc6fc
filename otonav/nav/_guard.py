"""Front-sector obstacle guard on a planar laser scan.

Scan convention follows ``sensor_msgs/LaserScan`` in the sensor frame (REP 103: x
forward, y left): beam ``i`` points at ``angle_min + i*angle_increment`` rad, CCW from
x; ranges are in m.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from otonav.params import GuardParams

__all__ = ("GuardParams", "guard_blocked")


@lru_cache(maxsize=16)
def _sector_mask(
    n: int, angle_min: float, angle_increment: float, half_angle: float
) -> NDArray[np.bool_]:
    """Read-only mask of beams whose wrapped angle lies within ±half_angle of 0."""
    angles = angle_min + angle_increment * np.arange(n, dtype=np.float64)
    wrapped = np.remainder(angles + math.pi, math.tau) - math.pi  # in [-pi, pi)
    mask = np.abs(wrapped) <= half_angle
    mask.flags.writeable = False
    return mask


def guard_blocked(
    ranges: NDArray[np.floating[Any]],
    angle_min: float,
    angle_increment: float,
    params: GuardParams,
    *,
    range_min: float = 0.0,
    range_max: float = math.inf,
) -> tuple[bool, float]:
    """Is anything too close straight ahead?

    A beam counts only if its angle is inside the front sector and its range is a
    valid return: finite, > 0, and within ``[range_min, range_max]`` (the LaserScan
    fields; by default no extra bound). So -1 (no hit), 0, +inf and NaN are ignored.
    ``-inf`` in the sector (REP 117: a return too close to measure) blocks, with
    ``closest`` = ``-inf``. Angles in rad, CCW from x forward; ranges in m.

    Returns ``(blocked, closest)``: ``closest`` is the smallest valid range in the
    sector (``inf`` if none), ``blocked`` is ``closest <= params.stop_distance``.
    ValueError if ``ranges`` is not 1-D or an angle is not finite.
    """
    if ranges.ndim != 1:
        raise ValueError(f"ranges must be 1-D, got shape {ranges.shape}")
    for name, angle in (("angle_min", angle_min), ("angle_increment", angle_increment)):
        if not math.isfinite(angle):
            raise ValueError(f"{name} must be finite, got {angle!r}")
    sector = _sector_mask(
        ranges.shape[0], float(angle_min), float(angle_increment), params.sector_half_angle
    )
    valid = np.isfinite(ranges)
    # Compare only finite entries so NaN never reaches a comparison.
    finite = np.where(valid, ranges, 0.0)
    valid &= (finite > 0.0) & (finite >= range_min) & (finite <= range_max)
    if np.isneginf(ranges[sector]).any():
        return True, -math.inf  # something is closer than the sensor can measure
    candidates = ranges[sector & valid]
    if candidates.size == 0:
        return False, math.inf
    closest = float(candidates.min())
    return closest <= params.stop_distance, closest
