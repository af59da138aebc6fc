"""The CAN tap's frames (flat messages of one layout per channel, ADR 0038) are the
Frames it built eagerly before: before first use the recorder packs them to the same
bytes, and from first use they are those Frames, field for field and type for type."""

from __future__ import annotations

import copy
import pickle
from collections.abc import Callable

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from otonav.hal.can._bus import RawFrame
from otonav.hal.can._tap import frame_layout, frames_of
from otonav.msgs import Frame, Header, Time
from otonav.msgs._flat import is_flat, reader
from otonav.record.cdr import encode

pytestmark = pytest.mark.unit


def eager_frames(channel: str, logged: list[tuple[float, RawFrame]]) -> list[Frame]:
    """The Frames as the tap built them before fixed layouts (ADR 0035's code)."""
    out: list[Frame] = []
    header: Header | None = None
    last = -1.0
    for t, raw in logged:
        if header is None or t != last:
            header, last = Header.fast(stamp=Time.from_seconds(t), frame_id=channel), t
        data = raw.data
        n = len(data)
        out.append(
            Frame.fast(
                header=header,
                id=raw.arbitration_id,
                is_rtr=raw.is_remote,
                is_extended=False,
                is_error=raw.is_error,
                dlc=n,
                data=tuple(data + bytes(8 - n)) if n <= 8 else tuple(data[:8]),
            )
        )
    return out


# Instants as the tap sees them (k ticks of 1 ms, several frames per instant) and odd
# ones (rounding at the nanosecond, large times).
TIMES = st.integers(0, 20_000).map(lambda k: k * 0.001) | st.floats(0.0, 2.0e9)
RAW = st.builds(
    RawFrame,
    st.integers(0, 2**32 - 1),  # a standard id, an error class, or anything uint32
    st.binary(min_size=0, max_size=10),  # a classic payload, or too long (cut to 8)
    st.booleans(),
    st.booleans(),
)
LOGGED = st.lists(st.tuples(TIMES, RAW), max_size=12).map(
    lambda frames: sorted(frames, key=lambda f: f[0])
)
CHANNELS = st.sampled_from(["can0", "vcan0", "x", "virtual_channel", ""])


@settings(max_examples=200, deadline=None)
@given(CHANNELS, LOGGED)
def test_the_tap_frames_are_the_eager_ones(
    channel: str, logged: list[tuple[float, RawFrame]]
) -> None:
    flats, eagers = frames_of(channel, logged), eager_frames(channel, logged)
    assert len(flats) == len(eagers)
    for flat, eager in zip(flats, eagers, strict=True):
        assert is_flat(flat)
        assert encode(flat) == encode(eager)  # the recorder's bytes, not built
        assert is_flat(flat)
        assert flat == eager
        assert type(flat) is Frame
        assert flat.model_dump() == eager.model_dump()
        assert flat.model_fields_set == eager.model_fields_set
        assert flat.header.model_fields_set == eager.header.model_fields_set
        assert flat.header.stamp.model_fields_set == eager.header.stamp.model_fields_set
        assert [type(b) for b in flat.data] == [int] * 8
        assert type(flat.is_rtr) is type(eager.is_rtr)
        assert encode(flat) == encode(eager)  # and once built


def test_a_frame_is_not_just_any_frame() -> None:
    # The comparison above would pass for two defaults: each varying field counts.
    base = (1.25, RawFrame(0x29, bytes([1, 2, 3]), False, True))
    flat = frames_of("can0", [base])[0]
    for other in (
        (1.26, base[1]),
        (1.25, RawFrame(0x2A, bytes([1, 2, 3]), False, True)),
        (1.25, RawFrame(0x29, bytes([1, 2, 4]), False, True)),
        (1.25, RawFrame(0x29, bytes([1, 2]), False, True)),
        (1.25, RawFrame(0x29, bytes([1, 2, 3]), True, True)),
        (1.25, RawFrame(0x29, bytes([1, 2, 3]), False, False)),
    ):
        assert encode(frames_of("can0", [other])[0]) != encode(flat)
        assert eager_frames("can0", [other])[0] != flat
    assert encode(frames_of("can1", [base])[0]) != encode(flat)


def test_every_use_a_subscriber_makes_sees_the_built_frame() -> None:
    logged = [(0.02, RawFrame(0x009 | 1 << 5, bytes(range(8)), False, False))]
    eager = eager_frames("can0", logged)[0]
    uses: dict[str, Callable[[Frame], object]] = {
        "field": lambda m: m.data,
        "nested": lambda m: m.header.stamp.to_seconds(),
        "eq": lambda m: m == eager,
        "repr": repr,
        "dump": lambda m: m.model_dump_json(),
        "copy": lambda m: copy.copy(m) == eager,
        "pickle": lambda m: pickle.loads(pickle.dumps(m)) == eager,
        "hash": lambda m: hash(m.header.stamp),
    }
    for name, use in uses.items():
        flat = frames_of("can0", logged)[0]
        assert use(flat) == use(eager), name
        assert type(flat) is Frame, name


def test_one_layout_per_channel() -> None:
    assert frame_layout("can0") is frame_layout("can0")
    assert frame_layout("can0") is not frame_layout("can1")
    assert frame_layout("can1").constant("header.frame_id") == "can1"


def test_a_reader_gets_the_bytes_as_the_frame_holds_them_without_building_it() -> None:
    logged = [(3.5, RawFrame(0x007, bytes([8, 0, 0, 0]), False, False))]
    flat, eager = frames_of("can0", logged)[0], eager_frames("can0", logged)[0]
    read = reader(Frame, "data", "dlc", "header.frame_id", "is_extended")
    assert read(flat) == read(eager) == ((8, 0, 0, 0, 0, 0, 0, 0), 4, "can0", False)
    assert is_flat(flat)
