"""Unit tests for otonav.nav._guard (front-sector obstacle guard)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from otonav.nav import GuardParams, guard_blocked

pytestmark = pytest.mark.unit

PARAMS = GuardParams()  # +-0.5 rad sector, stop at 0.35 m
N = 360
DEG = math.radians(1.0)  # one beam per degree


def scan(fill: float = 5.0, dtype: Any = np.float32) -> NDArray[np.floating[Any]]:
    """360 beams, angle_min = 0 (beam i points at i degrees, CCW from x forward)."""
    return np.full(N, fill, dtype=dtype)


def test_clear_when_all_beams_far() -> None:
    blocked, closest = guard_blocked(scan(5.0), 0.0, DEG, PARAMS)
    assert blocked is False
    assert closest == pytest.approx(5.0)


def test_blocked_when_beam_ahead_close() -> None:
    for index in (0, 10, 350):  # 0 deg, 10 deg left, 10 deg right (wraps past 2 pi)
        ranges = scan()
        ranges[index] = 0.2
        blocked, closest = guard_blocked(ranges, 0.0, DEG, PARAMS)
        assert blocked is True, index
        assert closest == pytest.approx(0.2)


def test_blocked_with_ros_style_angles() -> None:
    # angle_min = -pi: straight ahead is beam 180; beam 170 is 10 deg to the right.
    ranges = scan()
    ranges[170] = 0.3
    blocked, closest = guard_blocked(ranges, -math.pi, DEG, PARAMS)
    assert blocked is True
    assert closest == pytest.approx(0.3)


def test_ignores_close_beam_outside_front_sector() -> None:
    ranges = scan()
    for index in (40, 90, 180, 270, 320):  # 40 deg > 0.5 rad, sides, behind, -40 deg
        ranges[index] = 0.05
    ranges[20] = 1.5  # inside the sector, not close
    blocked, closest = guard_blocked(ranges, 0.0, DEG, PARAMS)
    assert blocked is False
    assert closest == pytest.approx(1.5)


def test_ignores_invalid_returns() -> None:
    ranges = scan(dtype=np.float64)
    ranges[0] = -1.0
    ranges[5] = math.inf
    ranges[355] = 0.0
    ranges[3] = math.nan
    ranges[8] = 2.0
    blocked, closest = guard_blocked(ranges, 0.0, DEG, PARAMS)
    assert blocked is False
    assert closest == pytest.approx(2.0)
    # Only invalid returns in the sector: nothing seen.
    invalid = np.array([-1.0, math.inf, 0.0, math.nan], dtype=np.float32)
    narrow = 0.01
    assert guard_blocked(invalid, -2 * narrow, narrow, PARAMS) == (False, math.inf)


def test_too_close_to_measure_is_blocked() -> None:
    """REP 117: -inf is a return closer than range_min. In the sector it blocks (it used
    to be dropped as invalid: an obstacle touching the lidar read as free space)."""
    ranges = scan(dtype=np.float32)
    ranges[3] = -math.inf
    assert guard_blocked(ranges, 0.0, DEG, PARAMS) == (True, -math.inf)
    ranges[3] = 5.0
    ranges[90] = -math.inf  # beside the robot, outside the sector: not in the way
    assert guard_blocked(ranges, 0.0, DEG, PARAMS) == (False, 5.0)


def test_respects_scan_range_limits() -> None:
    ranges = scan(dtype=np.float64)
    ranges[0] = 0.1  # below range_min: a sensor artefact
    ranges[1] = 0.3
    blocked, closest = guard_blocked(ranges, 0.0, DEG, PARAMS, range_min=0.12, range_max=10.0)
    assert blocked is True
    assert closest == pytest.approx(0.3)
    far = scan(fill=5.0, dtype=np.float64)
    assert guard_blocked(far, 0.0, DEG, PARAMS, range_max=4.0) == (False, math.inf)


def test_stop_distance_is_inclusive() -> None:
    ranges = scan(dtype=np.float64)
    ranges[0] = 0.35
    assert guard_blocked(ranges, 0.0, DEG, PARAMS) == (True, 0.35)
    ranges[0] = 0.36
    assert guard_blocked(ranges, 0.0, DEG, PARAMS) == (False, 0.36)


def test_rejects_bad_input() -> None:
    with pytest.raises(ValueError, match="1-D"):
        guard_blocked(np.ones((2, 3)), 0.0, DEG, PARAMS)
    with pytest.raises(ValueError, match="angle_increment"):
        guard_blocked(scan(), 0.0, math.nan, PARAMS)
    with pytest.raises(ValueError, match="sector_half_angle"):
        GuardParams(sector_half_angle=4.0)
    with pytest.raises(ValueError, match="stop_distance"):
        GuardParams(stop_distance=-0.1)


def reference(
    ranges: list[float], angle_min: float, increment: float, params: GuardParams
) -> tuple[bool, float]:
    """Scalar, loop-based restatement of the guard's rule."""
    closest = math.inf
    for i, r in enumerate(ranges):
        angle = math.atan2(math.sin(angle_min + i * increment), math.cos(angle_min + i * increment))
        if abs(angle) <= params.sector_half_angle and r == -math.inf:
            return True, -math.inf  # too close to measure
        if abs(angle) <= params.sector_half_angle and math.isfinite(r) and r > 0.0:
            closest = min(closest, r)
    return closest <= params.stop_distance, closest


beam = st.one_of(
    st.floats(min_value=0.0, max_value=10.0, allow_nan=False, allow_infinity=False),
    st.sampled_from([-1.0, 0.0, math.inf, -math.inf, math.nan]),
)


@settings(max_examples=150)
@given(
    ranges=st.lists(beam, min_size=0, max_size=64),
    angle_min=st.floats(min_value=-4.0, max_value=4.0, allow_nan=False, allow_infinity=False),
    increment=st.floats(min_value=0.01, max_value=0.5, allow_nan=False, allow_infinity=False),
    half_angle=st.floats(min_value=0.0, max_value=3.0, allow_nan=False, allow_infinity=False),
    stop=st.floats(min_value=0.0, max_value=5.0, allow_nan=False, allow_infinity=False),
)
def test_matches_scalar_reference(
    ranges: list[float], angle_min: float, increment: float, half_angle: float, stop: float
) -> None:
    params = GuardParams(sector_half_angle=half_angle, stop_distance=stop)
    # Keep beams away from the sector edge, where wrap-by-remainder and wrap-by-atan2
    # may round to opposite sides.
    for i in range(len(ranges)):
        angle = math.atan2(math.sin(angle_min + i * increment), math.cos(angle_min + i * increment))
        if abs(abs(angle) - half_angle) < 1e-9:
            return
    got = guard_blocked(np.array(ranges, dtype=np.float64), angle_min, increment, params)
    assert got == reference(ranges, angle_min, increment, params)
