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
        return self.add_batch([(channel_id, log_time, data, publish_time, sequence)]) > 0

    def add_batch(self, records: list[tuple[int, int, bytes, int, int]]) -> int:
        """:meth:`add_message` for each ``(channel_id, log_time, data, publish_time,
        sequence)`` in order, with the writer's state in locals and the records joined
        into one write per chunk: the same bytes, statistics and index as the stock
        writer (a chunk is finished after the message that takes it past the chunk
        size). Returns how many chunks were finished. The only copy of the fast path:
        a single message comes here too (:meth:`add_message_and_check`)."""
        if not SUPPORTED:
            before = self._chunks_written()
            for channel_id, log_time, data, publish_time, sequence in records:
                super().add_message(channel_id, log_time, data, publish_time, sequence)
            return self._chunks_written() - before
        stats: Any = self._Writer__statistics  # type: ignore[attr-defined]
        limit: int = self._Writer__chunk_size  # type: ignore[attr-defined]
        counts = stats.channel_message_counts
        pack = _HEADER.pack
        finished = 0
        start = 0
        while start < len(records):
            chunk: Any = self._Writer__chunk_builder  # type: ignore[attr-defined]
            buffer = chunk.record_writer._buffer
            indices = chunk.message_indices
            pos = buffer.tell()
            parts: list[bytes] = []
            first = chunk.num_messages == 0
            chunk_start, chunk_end = chunk.message_start_time, chunk.message_end_time
            stats_empty = stats.message_count == 0
            stats_start, stats_end = stats.message_start_time, stats.message_end_time
            full = False
            i = start
            for i in range(start, len(records)):
                channel_id, log_time, data, publish_time, sequence = records[i]
                if stats_empty or log_time < stats_start:
                    stats_start, stats_empty = log_time, False
                if log_time > stats_end:
                    stats_end = log_time
                counts[channel_id] += 1
                if first or log_time < chunk_start:
                    chunk_start, first = log_time, False
                if log_time > chunk_end:
                    chunk_end = log_time
                index = indices.get(channel_id)
                if index is None:
                    index = indices[channel_id] = _MessageIndex(channel_id=channel_id, records=[])
                index.records.append((log_time, pos))
                parts.append(
                    pack(
                        _MESSAGE_OPCODE,
                        _FIELDS_LENGTH + len(data),
                        channel_id,
                        sequence,
                        log_time,
                        publish_time,
                    )
                )
                parts.append(data)
                pos += _HEADER.size + len(data)
                if pos > limit:
                    full = True
                    break
            taken = i + 1 - start
            buffer.write(b"".join(parts))
            chunk.num_messages += taken
            chunk.message_start_time, chunk.message_end_time = chunk_start, chunk_end
            stats.message_count += taken
            stats.message_start_time, stats.message_end_time = stats_start, stats_end
            start = i + 1
            if full:
                self._Writer__finalize_chunk()  # type: ignore[attr-defined]
                finished += 1
        return finished

    def _chunks_written(self) -> int:
        return int(self._Writer__statistics.chunk_count)  # type: ignore[attr-defined]
