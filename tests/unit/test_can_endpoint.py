"""Layer 1: the python-can boundary (``otonav.hal.can._bus``) on python-can's in-process
``virtual`` interface: what a receiver gets is what python-can itself would give."""

from __future__ import annotations

import copy
import itertools
from typing import Any

import can
import pytest

from otonav.hal.can import RawFrame, open_endpoint
from otonav.hal.can._bus import _Outgoing

pytestmark = pytest.mark.unit

_SLOTS = [s for s in can.Message.__slots__ if s != "__weakref__"]


def _slots(message: can.Message) -> dict[str, object]:
    return {name: getattr(message, name) for name in _SLOTS}


@pytest.mark.parametrize(
    ("data", "remote", "error", "channel", "fd"),
    [
        (bytes(range(8)), False, False, None, False),
        (b"", False, False, "vcan0", False),
        (b"\x01\x02", True, False, 3, False),
        (b"\xff" * 8, False, True, None, True),
    ],
)
def test_the_lean_copy_equals_python_cans_own_deep_copy(
    data: bytes, remote: bool, error: bool, channel: str | int | None, fd: bool
) -> None:
    fields: dict[str, Any] = dict(
        timestamp=12.34,
        arbitration_id=0x069,
        is_extended_id=False,
        is_remote_frame=remote,
        is_error_frame=error,
        channel=channel,
        dlc=len(data),
        data=data,
        is_fd=fd,
        is_rx=False,
        bitrate_switch=fd,
        error_state_indicator=fd,
    )
    lean = _Outgoing(**fields)
    lean.data = data  # type: ignore[assignment]  # what the endpoint does: immutable bytes
    reference = copy.deepcopy(can.Message(**fields))
    got = copy.deepcopy(lean)
    assert type(got) is can.Message  # receivers get plain python-can messages
    assert _slots(got) == _slots(reference)
    assert {k: type(v) for k, v in _slots(got).items()} == {
        k: type(v) for k, v in _slots(reference).items()
    }
    assert got.data is not lean.data  # a copy of its own, like python-can's


def test_frames_cross_a_virtual_bus_intact_and_in_order() -> None:
    a = open_endpoint("virtual", "test-endpoint-order")
    b = open_endpoint("virtual", "test-endpoint-order")
    try:
        sent = [
            RawFrame(ident, bytes(itertools.islice(itertools.cycle(range(256)), ident, ident + n)))
            for ident, n in zip(range(0x001, 0x7FF, 97), itertools.cycle(range(9)), strict=False)
        ]
        for i, frame in enumerate(sent):
            a.send_data(frame.arbitration_id, frame.data, timestamp=0.01 * i)
        a.send(RawFrame(0x040, bytes(8), is_error=True))
        a.send(RawFrame(0x123, b"", is_remote=True))
        got = b.poll()
        assert got == [*sent, RawFrame(0x040, bytes(8), True), RawFrame(0x123, b"", False, True)]
        assert all(type(f.data) is bytes for f in got)
        assert a.poll() == []  # an endpoint does not hear itself
    finally:
        a.close()
        b.close()
