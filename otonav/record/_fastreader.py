"""Reading the messages of chosen channels from an indexed MCAP file, fast.

mcap's reader parses every record of every chunk into an object through a byte stream
(``ReadDataStream.read8``...): on the acceptance recording that was a third of a
replay's wall time. This reads each chunk with mcap's own ``Chunk`` record and
decompression (``get_chunk_data_stream``) and slices out only the messages of the wanted
channels, in file order. Only chunks whose message index lists a wanted channel are
read, and each one is checked against its CRC (the CRC-32 of its uncompressed records; 0
means none was written): a chunk that fails it, or does not decompress, raises
:class:`ChunkDamageError` instead of handing on damaged data as recorded.

Where the messages are inside a chunk comes from the chunk's message indexes (the
records after it that list, per channel, each message's log time and offset): the
navigator's replay wants 2,241 of the acceptance recording's 7,215 messages, and walking
every record in Python was half the read (3.2 -> 1.8 ms). The indexes sit outside the
chunk and its CRC, so they are checked against what they point at (a message record of
their channel with their log time, inside the chunk) and, over the file, against the
summary's message count per channel; where any of that fails, or a chunk has no index,
the chunk is walked record by record instead, the CRC-checked truth.

The MCAP format is a published spec (records: opcode u8, length u64, content; Message:
channel u16, sequence u32, log time u64, publish time u64, data; MessageIndex: channel
u16, then u32 bytes of (log time u64, offset u64) pairs); a test checks this reader
against mcap's on recordings, damaged indexes included.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Collection
from io import BytesIO
from typing import IO, Any

from mcap.data_stream import ReadDataStream
from mcap.records import Chunk
from mcap.stream_reader import get_chunk_data_stream

from otonav.record._verify import Damage, _one_line

__all__ = ("ChunkDamageError", "read_raw_messages")

_MESSAGE = 0x05
_MESSAGE_INDEX = 0x07
_RECORD = struct.Struct("<BQ")
_MESSAGE_HEAD = struct.Struct("<HIQQ")
_INDEX_HEAD = struct.Struct("<BQHI")
_ENTRY = struct.Struct("<QQ")

RawMessage = tuple[int, int, bytes]
"""(channel id, log time ns, data)."""


class ChunkDamageError(ValueError):
    """A chunk that fails its CRC or does not decompress."""

    def __init__(self, damage: Damage) -> None:
        super().__init__(damage.describe())
        self.damage = damage


class _IndexMismatch(Exception):
    """A message index that does not describe its chunk: walk the chunk instead."""


def _damage(index: Any, chunk: Chunk, problem: str) -> Damage:
    return Damage(
        index.chunk_start_offset, problem, chunk.message_start_time, chunk.message_end_time
    )


def read_raw_messages(
    stream: IO[bytes], summary: Any, channel_ids: Collection[int] | None
) -> list[RawMessage]:
    """``(channel id, log time ns, data)`` of every message on ``channel_ids`` (all when
    None), in file order. ``summary`` is the file's mcap ``Summary`` (needs its chunk
    indexes). Raises :class:`ChunkDamageError` at the first damaged chunk read."""
    wanted = None if channel_ids is None else frozenset(channel_ids)
    chunks = sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)
    out: list[RawMessage] = []
    trusted_indexes = False
    for index in chunks:
        offsets = index.message_index_offsets
        if wanted is not None and offsets and wanted.isdisjoint(offsets):
            continue
        data, _chunk, indexes = _read_chunk(stream, index)
        if wanted is None or not offsets:
            out.extend(_walk(data, wanted))
            continue
        try:
            out.extend(_through_indexes(data, indexes, index, wanted))
            trusted_indexes = True
        except _IndexMismatch:
            out.extend(_walk(data, wanted))
    if trusted_indexes and not _counts_agree(out, summary, wanted):
        # An index lost entries, or lists a channel in the wrong chunks: walk them all.
        return [m for index in chunks for m in _walk(_read_chunk(stream, index)[0], wanted)]
    return out


def _counts_agree(messages: list[RawMessage], summary: Any, wanted: frozenset[int] | None) -> bool:
    """Whether ``messages`` hold as many messages per wanted channel as the summary's
    statistics say the file has (True when it has none to say)."""
    counts = getattr(getattr(summary, "statistics", None), "channel_message_counts", None)
    if counts is None:
        return True
    found: dict[int, int] = {}
    for channel, _time, _data in messages:
        found[channel] = found.get(channel, 0) + 1
    return all(found.get(c, 0) == counts.get(c, 0) for c in (wanted or counts))


def _read_chunk(stream: IO[bytes], index: Any) -> tuple[bytes, Chunk, bytes]:
    """The chunk's uncompressed records (CRC checked), the chunk, and the raw bytes of
    its message indexes (those follow the chunk; one read for both)."""
    stream.seek(index.chunk_start_offset)
    blob = stream.read(index.chunk_length + index.message_index_length)
    chunk = Chunk.read(ReadDataStream(BytesIO(blob[9 : index.chunk_length])))
    try:
        data_stream, length = get_chunk_data_stream(chunk)
        data: bytes = data_stream.read(length)
    except Exception as exc:  # zstd/lz4 errors have no common type
        raise ChunkDamageError(
            _damage(index, chunk, f"does not decode ({_one_line(exc)})")
        ) from None
    crc = zlib.crc32(data)
    if chunk.uncompressed_crc not in (0, crc):
        problem = f"CRC mismatch (recorded {chunk.uncompressed_crc:#010x}, computed {crc:#010x})"
        raise ChunkDamageError(_damage(index, chunk, problem))
    return data, chunk, blob[index.chunk_length :]


def _walk(data: bytes, wanted: frozenset[int] | None) -> list[RawMessage]:
    """Every record of the chunk in turn: the messages of ``wanted`` channels."""
    out: list[RawMessage] = []
    pos = 0
    end = len(data)
    while pos < end:
        opcode, size = _RECORD.unpack_from(data, pos)
        pos += 9
        if opcode == _MESSAGE:
            channel, _seq, log_time, _publish = _MESSAGE_HEAD.unpack_from(data, pos)
            if wanted is None or channel in wanted:
                out.append((channel, log_time, data[pos + 22 : pos + size]))
        pos += size
    return out


def _through_indexes(
    data: bytes, indexes: bytes, index: Any, wanted: frozenset[int]
) -> list[RawMessage]:
    """The wanted messages at the offsets the chunk's message indexes give, each checked
    to be a message record of that channel and log time inside the chunk; raises
    :class:`_IndexMismatch` otherwise."""
    base = index.chunk_start_offset + index.chunk_length
    entries: list[tuple[int, int, int]] = []  # (offset, channel, log time)
    end = len(data)
    try:
        for channel in wanted:
            at = index.message_index_offsets.get(channel)
            if at is None:
                continue
            pos = at - base
            opcode, _length, channel_id, size = _INDEX_HEAD.unpack_from(indexes, pos)
            if opcode != _MESSAGE_INDEX or channel_id != channel or size % 16:
                raise _IndexMismatch
            pos += _INDEX_HEAD.size
            if pos + size > len(indexes):
                raise _IndexMismatch
            pairs = _ENTRY.iter_unpack(indexes[pos : pos + size])
            entries.extend((offset, channel, log_time) for log_time, offset in pairs)
        entries.sort()
        out: list[RawMessage] = []
        for offset, channel, log_time in entries:
            opcode, size = _RECORD.unpack_from(data, offset)
            head = _MESSAGE_HEAD.unpack_from(data, offset + 9)
            stop = offset + 9 + size
            if opcode != _MESSAGE or head[0] != channel or head[2] != log_time or stop > end:
                raise _IndexMismatch
            out.append((channel, log_time, data[offset + 31 : stop]))
    except struct.error:
        raise _IndexMismatch from None
    return out
