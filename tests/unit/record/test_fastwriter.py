"""FastWriter writes exactly the bytes mcap's stock Writer writes."""

from __future__ import annotations

import io

import pytest
from mcap.writer import CompressionType, Writer

from otonav.record._fastwriter import SUPPORTED, FastWriter

pytestmark = pytest.mark.unit


def _write(kind: type[Writer]) -> bytes:
    out = io.BytesIO()
    writer = kind(out, chunk_size=4096, compression=CompressionType.ZSTD)
    writer.start(profile="ros2", library="test")
    schema = writer.register_schema("pkg/msg/T", "ros2msg", b"int32 x")
    channels = [writer.register_channel(f"/t{i}", "cdr", schema) for i in range(3)]
    for n in range(2000):
        # Out-of-order times too: the statistics and indexes must track min and max.
        t = n * 1_000_000 - (500_000 if n % 7 == 3 else 0)
        writer.add_message(channels[n % 3], t, bytes([n % 251]) * (n % 97), t + 1, n)
    writer.finish()  # type: ignore[no-untyped-call]
    return out.getvalue()


def test_supported_on_the_pinned_mcap() -> None:
    assert SUPPORTED  # the fast path is really exercised below


def test_fast_writer_is_byte_identical_to_the_stock_writer() -> None:
    assert _write(FastWriter) == _write(Writer)
