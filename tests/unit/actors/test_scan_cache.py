"""The shared scan conversions: the ranges array made once per scan, and the cheap
lower bound the safety layer tests before the exact nearest return."""

from __future__ import annotations

import math

import numpy as np
import pytest

from otonav.actors._scan_cache import nearest_bound_of, nearest_of, points_of
from otonav.msgs import LaserScan

pytestmark = pytest.mark.unit


def _scan(ranges: list[float]) -> LaserScan:
    n = len(ranges)
    return LaserScan(
        angle_min=-math.pi,
        angle_max=math.pi - 2 * math.pi / n,
        angle_increment=2 * math.pi / n,
        range_min=0.12,
        range_max=8.0,
        ranges=tuple(ranges),
    )


def test_the_bound_never_exceeds_the_nearest_return_and_is_within_the_offset() -> None:
    rng = np.random.default_rng(4)
    odd = [math.nan, math.inf, 9.5, -math.inf, 0.05]
    tight = 0
    for trial in range(400):
        ranges = rng.uniform(0.12, 8.5, 90).tolist()
        for i in rng.integers(0, 90, int(rng.integers(0, 6))).tolist():
            ranges[i] = odd[int(rng.integers(0, 3 if trial % 3 else 5))]
        offset = float(rng.uniform(-0.2, 0.2))
        scan = _scan(ranges)
        bound, exact = nearest_bound_of(scan, offset), nearest_of(scan, offset)
        assert bound <= exact
        if math.isfinite(exact):
            assert exact - bound <= 2 * abs(offset) + 1e-12
            tight += exact - bound < 0.01
        if any(r < 0.12 for r in ranges):  # a blocked beam: the exact distance
            assert bound == exact
    assert tight > 20  # and often nearly exact (a return near the laser's axis)


def test_no_return_is_infinitely_far_and_all_nan_too() -> None:
    assert nearest_bound_of(_scan([math.inf] * 8), 0.1) == math.inf
    assert nearest_bound_of(_scan([math.nan] * 8), 0.1) == math.inf
    assert nearest_of(_scan([math.nan] * 8), 0.1) == math.inf


def test_one_scan_is_converted_once_and_its_array_is_read_only() -> None:
    scan = _scan([1.0, 2.0, 3.0, 4.0])
    first = points_of(scan, 0.1)
    assert points_of(scan, 0.1) is first
    other = _scan([1.0, 2.0, 3.0, 4.0])
    assert points_of(other, 0.1) is not first
    from otonav.actors._scan_cache import _wire

    ranges = _wire(other)[0]
    assert _wire(other)[0] is ranges
    with pytest.raises(ValueError, match="read-only"):
        ranges[0] = 0.0
