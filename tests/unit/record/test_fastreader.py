"""The fast reader gives exactly the messages mcap's own reader gives, in file order,
whether it finds them through the chunks' message indexes or by walking the chunks, and
a message index that does not describe its chunk (the indexes are not covered by the
chunk's CRC) never changes what it reads."""

from __future__ import annotations

import io
import struct

import pytest
from mcap.reader import make_reader
from mcap.writer import CompressionType, IndexType, Writer

from otonav.record import _fastreader as fastreader
from otonav.record._fastreader import ChunkDamageError, read_raw_messages

pytestmark = pytest.mark.unit


def _recording(index_types: IndexType = IndexType.ALL) -> bytes:
    out = io.BytesIO()
    writer = Writer(out, chunk_size=4096, compression=CompressionType.ZSTD, index_types=index_types)
    writer.start(profile="ros2", library="test")
    schema = writer.register_schema("pkg/msg/T", "ros2msg", b"int32 x")
    channels = [writer.register_channel(f"/t{i}", "cdr", schema) for i in range(4)]
    for n in range(3000):
        # Uneven channels and sizes, and times out of order, as a backpressured
        # publisher leaves them: file order is what counts.
        channel = channels[0] if n % 5 < 2 else channels[1 + n % 3]
        t = n * 1_000_000 - (500_000 if n % 7 == 3 else 0)
        writer.add_message(channel, t, n.to_bytes(4, "little") * (n % 41), t + 1, n)
    writer.finish()  # type: ignore[no-untyped-call]
    return out.getvalue()


def _mcap_reads(data: bytes, channels: set[int] | None) -> list[tuple[int, int, bytes]]:
    reader = make_reader(io.BytesIO(data))
    return [
        (m.channel_id, m.log_time, m.data)
        for _schema, channel, m in reader.iter_messages(log_time_order=False)
        if channels is None or channel.id in channels
    ]


def _read(data: bytes, channels: set[int] | None) -> list[tuple[int, int, bytes]]:
    stream = io.BytesIO(data)
    summary = make_reader(stream).get_summary()
    return read_raw_messages(stream, summary, channels)


CHANNEL_SETS = [None, {1}, {2}, {1, 3}, {2, 3, 4}, {1, 2, 3, 4}, set()]


@pytest.mark.parametrize("channels", CHANNEL_SETS)
def test_the_indexed_read_is_mcaps_read(channels: set[int] | None) -> None:
    data = _recording()
    expected = _mcap_reads(data, channels)
    assert bool(expected) == (channels != set())
    assert _read(data, channels) == expected


def test_the_indexes_are_used(monkeypatch: pytest.MonkeyPatch) -> None:
    walked: list[int] = []
    walk = fastreader._walk

    def counted(data: bytes, wanted: frozenset[int] | None) -> list[fastreader.RawMessage]:
        walked.append(1)
        return walk(data, wanted)

    monkeypatch.setattr(fastreader, "_walk", counted)
    data = _recording()
    assert _read(data, {2, 3}) == _mcap_reads(data, {2, 3})
    assert walked == []


def test_chunks_without_message_indexes_are_walked() -> None:
    data = _recording(IndexType.CHUNK)
    summary = make_reader(io.BytesIO(data)).get_summary()
    assert summary is not None
    assert all(not c.message_index_offsets for c in summary.chunk_indexes)
    for channels in CHANNEL_SETS:
        assert _read(data, channels) == _mcap_reads(data, channels)


def _index_of(data: bytes, channel: int, nth_chunk: int = 3) -> int:
    """File offset of ``channel``'s message index record after the nth chunk."""
    summary = make_reader(io.BytesIO(data)).get_summary()
    assert summary is not None
    chunks = sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)
    return int(chunks[nth_chunk].message_index_offsets[channel])


def _patched(data: bytes, at: int, fmt: str, change: object) -> bytes:
    out = bytearray(data)
    (value,) = struct.unpack_from(fmt, out, at)
    struct.pack_into(fmt, out, at, change(value))  # type: ignore[operator]
    return bytes(out)


@pytest.mark.parametrize(
    ("what", "field", "fmt", "change"),
    [
        # An entry's offset moved by one byte, and onto the next message of its chunk.
        ("offset", 15 + 8, "<Q", lambda v: v + 1),
        ("offset", 15 + 8, "<Q", lambda v: v + 40),
        # An entry's log time.
        ("log time", 15, "<Q", lambda v: v + 1),
        # The index lists one message fewer (its last): only the file's counts tell.
        ("records length", 11, "<I", lambda v: v - 16),
        # The index is for another channel, or not an index at all.
        ("channel", 9, "<H", lambda v: v + 1),
        ("opcode", 0, "<B", lambda v: 0x05),
    ],
)
def test_a_damaged_message_index_changes_nothing_read(
    what: str, field: int, fmt: str, change: object
) -> None:
    data = _recording()
    at = _index_of(data, 1) + field
    damaged = _patched(data, at, fmt, change)
    assert damaged != data, what
    for channels in ({1}, {1, 3}, None):
        assert _read(damaged, channels) == _mcap_reads(data, channels), (what, channels)


def test_a_damaged_chunk_is_still_refused() -> None:
    data = _recording()
    summary = make_reader(io.BytesIO(data)).get_summary()
    assert summary is not None
    chunk = sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)[2]
    crc_at = chunk.chunk_start_offset + 9 + 24  # past opcode, length, times, size
    damaged = _patched(data, crc_at, "<I", lambda v: v ^ 1)
    with pytest.raises(ChunkDamageError, match="CRC mismatch"):
        _read(damaged, {1})
