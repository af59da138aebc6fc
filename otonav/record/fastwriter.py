"""A faster ``add_message`` for mcap's :class:`~mcap.writer.Writer`.

The stock method builds a ``Message`` record object and writes it field by field (five
``struct.pack`` calls and a seek-back for the length) into the chunk: 23 µs of a
profiled 30 s run's per-message recording cost. This does the same bookkeeping
(statistics, the chunk's time range and message index) and writes the record with one
``pack``. It reaches into the writer's private state, so it is enabled only for the mcap
version it was written against (1.6.x, pinned in constraints.txt); on any other version
the stock method runs. The reader tests (every file is read back by mcap's own reader and
mcap_ros2's decoder) would catch a mismatch.
"""

from __future__ import annotations

import struct
from importlib.metadata import version
from typing import Any

from mcap.records import MessageIndex
from mcap.writer import Writer

_MESSAGE_OPCODE = 0x05
# opcode u8, record length u64, channel_id u16, sequence u32, log_time u64, publish_time u64
_HEADER = struct.Struct("<BQHIQQ")
_FIELDS_LENGTH = 2 + 4 + 8 + 8
_INDEX_HEADER = struct.Struct("<BQHI")
"""opcode u8, record length u64, channel_id u16, entries' byte length u32"""
_MESSAGE_INDEX_OPCODE = 0x07
SUPPORTED = version("mcap").startswith("1.6.")


class _MessageIndex(MessageIndex):
    """A chunk's index of one channel, written with one ``pack``: mcap's own writes
    each entry as two ``write8`` calls (a ``struct.pack`` and a ``BytesIO.write`` each,
    ~2 per recorded message). The same record, byte for byte."""

    def write(self, stream: Any) -> None:
        records = self.records
        n = len(records)
        stream.write(
            _INDEX_HEADER.pack(_MESSAGE_INDEX_OPCODE, 2 + 4 + 16 * n, self.channel_id, 16 * n)
            + struct.pack(f"<{2 * n}Q", *[value for entry in records for value in entry])
        )


class FastWriter(Writer):
    def add_message(
        self,
        channel_id: int,
        log_time: int,
        data: bytes,
        publish_time: int,
        sequence: int = 0,
    ) -> None:
        self.add_message_and_check(channel_id, log_time, data, publish_time, sequence)

    def add_message_and_check(
        self, channel_id: int, log_time: int, data: bytes, publish_time: int, sequence: int
    ) -> bool:
        """:meth:`add_message`; True when that finished a chunk (it went to the stream)."""
        if not SUPPORTED:
            before = self._chunks_written()
            super().add_message(channel_id, log_time, data, publish_time, sequence)
            return self._chunks_written() != before
        stats: Any = self._Writer__statistics  # type: ignore[attr-defined]
        if stats.message_count == 0 or log_time < stats.message_start_time:
            stats.message_start_time = log_time
        if log_time > stats.message_end_time:
            stats.message_end_time = log_time
        stats.channel_message_counts[channel_id] += 1
        stats.message_count += 1
        chunk: Any = self._Writer__chunk_builder  # type: ignore[attr-defined]
        if chunk.num_messages == 0 or log_time < chunk.message_start_time:
            chunk.message_start_time = log_time
        if log_time > chunk.message_end_time:
            chunk.message_end_time = log_time
        buffer = chunk.record_writer._buffer  # a BytesIO: its write and tell directly
        index = chunk.message_indices.get(channel_id)
        if index is None:
            index = chunk.message_indices[channel_id] = _MessageIndex(
                channel_id=channel_id, records=[]
            )
        index.records.append((log_time, buffer.tell()))
        chunk.num_messages += 1
        buffer.write(
            _HEADER.pack(
                _MESSAGE_OPCODE,
                _FIELDS_LENGTH + len(data),
                channel_id,
                sequence,
                log_time,
                publish_time,
            )
        )
        buffer.write(data)
        if buffer.tell() > self._Writer__chunk_size:  # type: ignore[attr-defined]
            self._Writer__finalize_chunk()  # type: ignore[attr-defined]
            return True
        return False

    def _chunks_written(self) -> int:
        return int(self._Writer__statistics.chunk_count)  # type: ignore[attr-defined]
