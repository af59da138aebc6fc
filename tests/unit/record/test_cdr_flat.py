"""A fixed-layout message's CDR (one precompiled pack) is the field-by-field encoder's,
byte for byte: for random values, signed zeros, NaN, infinities and extremes, and for
layouts whose strings, sequences and float32 fields move the offsets around."""

from __future__ import annotations

import math
import struct
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from otonav.actors._bridge import CLOCK, IMU, ODOM, TF
from otonav.hal.can._tap import frame_layout
from otonav.msgs import (
    DiagnosticArray,
    DiagnosticStatus,
    Header,
    KeyValue,
    LaserScan,
    Log,
    Message,
    Time,
)
from otonav.msgs._flat import FlatLayout, is_flat, materialize
from otonav.record.cdr import encode

pytestmark = pytest.mark.unit

FLOATS = st.floats(allow_nan=True, allow_infinity=True) | st.sampled_from(
    [0.0, -0.0, math.nan, -math.nan, math.inf, -math.inf, 1.7976931348623157e308, 5e-324]
)
SEC = st.integers(-(2**31), 2**31 - 1)
NSEC = st.integers(0, 2**32 - 1)


def _field_by_field(layout: FlatLayout[Any], values: tuple[Any, ...]) -> bytes:
    """The same message built, then encoded by the generated per-type encoder."""
    built = materialize(layout(*values))
    assert not is_flat(built)
    return encode(built)


def _check(layout: FlatLayout[Any], values: tuple[Any, ...]) -> None:
    flat = layout(*values)
    assert encode(flat) == _field_by_field(layout, values)
    assert is_flat(flat)  # encoding did not build it


@settings(max_examples=200, deadline=None)
@given(SEC, NSEC, st.lists(FLOATS, min_size=6, max_size=6))
def test_odometry_bytes(sec: int, nsec: int, floats: list[float]) -> None:
    _check(ODOM, (sec, nsec, *floats))


@settings(max_examples=100, deadline=None)
@given(SEC, NSEC, st.lists(FLOATS, min_size=4, max_size=4))
def test_tf_bytes(sec: int, nsec: int, floats: list[float]) -> None:
    _check(TF, (sec, nsec, *floats))


@settings(max_examples=100, deadline=None)
@given(SEC, NSEC, st.lists(FLOATS, min_size=10, max_size=10))
def test_imu_bytes(sec: int, nsec: int, floats: list[float]) -> None:
    _check(IMU, (sec, nsec, *floats))


@settings(max_examples=50, deadline=None)
@given(SEC, NSEC)
def test_clock_bytes(sec: int, nsec: int) -> None:
    _check(CLOCK, (sec, nsec))


@settings(max_examples=200, deadline=None)
@given(
    st.text(max_size=9),  # the channel: a string before the numbers moves their offsets
    SEC,
    NSEC,
    st.integers(0, 2**32 - 1),
    st.booleans(),
    st.booleans(),
    st.integers(0, 255),
    st.binary(min_size=8, max_size=8),
)
def test_can_frame_bytes(
    channel: str,
    sec: int,
    nsec: int,
    ident: int,
    rtr: bool,
    error: bool,
    dlc: int,
    data: bytes,
) -> None:
    # The tap's layout: the 8 data bytes are one bytes value (an "8s" item).
    layout = frame_layout(channel)
    assert layout.byte_paths == {layout.index("data")}
    _check(layout, (sec, nsec, ident, rtr, error, dlc, data))
    assert materialize(layout(sec, nsec, ident, rtr, error, dlc, data)).data == tuple(data)


@settings(max_examples=100, deadline=None)
@given(st.lists(st.integers(0, 255), min_size=3, max_size=3), st.integers(0, 2**32 - 1))
def test_elements_of_a_byte_array_as_numbers(elements: list[int], ident: int) -> None:
    layout = FlatLayout(frame_layout("vcan1").template, ("data.7", "id", "data.0", "data.3"))
    assert not layout.byte_paths
    _check(layout, (*elements[:1], ident, *elements[1:]))


def test_elements_of_a_sequence_can_vary() -> None:
    ranges = FlatLayout(SCAN.template, ("ranges.2", "ranges.0"))
    _check(ranges, (0.5, 7.0))
    assert materialize(ranges(0.5, 7.0)).ranges == (7.0, 2.0, 0.5)


def test_bytes_only_for_an_array_of_bytes() -> None:
    # Small ints in the template of a float32[]: FlatLayout takes it for bytes, the CDR
    # packer refuses it, naming the path.
    odd = FlatLayout(SCAN.template.model_copy(update={"intensities": (1, 2)}), ("intensities",))
    with pytest.raises(ValueError, match="'intensities' is not a primitive of sensor_msgs"):
        encode(odd(b"\x01\x02"))


def test_the_sign_of_zero_and_nan_bits_survive() -> None:
    values = (0, 0, -0.0, 0.0, -0.0, math.nan, -math.inf, -0.0)
    data = encode(ODOM(*values))
    assert data == _field_by_field(ODOM, values)
    assert struct.pack("<d", -0.0) in data


@pytest.mark.parametrize(
    ("layout", "bad", "match"),
    [
        (CLOCK, (2**31, 0), "cannot encode rosgraph_msgs/msg/Clock"),
        (CLOCK, (0, -1), "cannot encode rosgraph_msgs/msg/Clock"),
    ],
)
def test_values_the_ros_type_cannot_hold_fail_as_they_do_field_by_field(
    layout: FlatLayout[Any], bad: tuple[Any, ...], match: str
) -> None:
    with pytest.raises(ValueError, match=match):
        encode(layout(*bad))
    with pytest.raises(ValueError, match=match):
        _field_by_field(layout, bad)


# Layouts the bridge does not use, whose strings, sequences, uint8/uint32 and float32
# fields put the varying values at every kind of offset.
SCAN = FlatLayout(
    LaserScan.fast(
        header=Header.fast(stamp=Time.fast(sec=0, nanosec=0), frame_id="laser_frame"),
        angle_min=-1.0,
        angle_max=1.0,
        angle_increment=0.5,
        time_increment=0.0,
        scan_time=0.1,
        range_min=0.1,
        range_max=8.0,
        ranges=(1.0, 2.0, math.inf),
        intensities=(),
    ),
    ("header.stamp.nanosec", "angle_increment", "range_max", "angle_min"),
)
LOG = FlatLayout(
    Log.fast(
        stamp=Time.fast(sec=0, nanosec=0),
        level=20,
        name="bridge",
        msg="odd length",
        file="x.py",
        function="f",
        line=0,
    ),
    ("line", "level", "stamp.sec"),
)
DIAG = FlatLayout(
    DiagnosticArray.fast(
        header=Header.fast(stamp=Time.fast(sec=0, nanosec=0), frame_id=""),
        status=(
            DiagnosticStatus.fast(
                level=0,
                name="a",
                message="ok",
                hardware_id="hw",
                values=(KeyValue.fast(key="k", value="vv"),),
            ),
            DiagnosticStatus.fast(level=1, name="bcd", message="", hardware_id="", values=()),
        ),
    ),
    ("status.1.level", "header.stamp.sec", "status.0.level"),
)


@settings(max_examples=100, deadline=None)
@given(
    NSEC,
    st.floats(width=32, allow_nan=False),
    st.floats(width=32),
    st.floats(width=32, allow_infinity=False),
)
def test_a_scan_layout_with_float32_fields(nsec: int, a: float, b: float, c: float) -> None:
    _check(SCAN, (nsec, a, b, c))


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(0, 255), SEC)
def test_a_layout_after_strings_of_odd_lengths(line: int, level: int, sec: int) -> None:
    _check(LOG, (line, level, sec))


@settings(max_examples=50, deadline=None)
@given(st.integers(0, 255), SEC, st.integers(0, 255))
def test_a_layout_inside_a_sequence_of_messages(a: int, sec: int, b: int) -> None:
    _check(DIAG, (a, sec, b))


def test_a_float32_value_too_large_fails_as_it_does_field_by_field() -> None:
    with pytest.raises(ValueError, match="cannot encode sensor_msgs/msg/LaserScan"):
        encode(SCAN(0, 1e300, 1.0, 1.0))
    with pytest.raises(ValueError, match="cannot encode sensor_msgs/msg/LaserScan"):
        _field_by_field(SCAN, (0, 1e300, 1.0, 1.0))


def test_the_packer_is_checked_and_cached_on_its_layout() -> None:
    layout = FlatLayout(CLOCK.template, ("clock.nanosec",))
    assert layout.cdr is None
    encode(layout(7))
    assert layout.cdr is not None
    assert "_pack" in (layout.cdr.__doc__ or "")
    assert isinstance(CLOCK.template, Message)
