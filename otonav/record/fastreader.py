"""Reading the messages of chosen channels from an indexed MCAP file, fast.

mcap's reader parses every record of every chunk into an object through a byte stream
(``ReadDataStream.read8``...): on the acceptance recording that was a third of a
replay's wall time. This reads each chunk with mcap's own ``Chunk`` record and
decompression (``get_chunk_data_stream``), then walks the uncompressed records with
``struct.unpack_from`` and slices out only the messages of the wanted channels, in file
order. Only chunks whose message index lists a wanted channel are read. The MCAP format
is a published spec (records: opcode u8, length u64, content; Message: channel u16,
sequence u32, log time u64, publish time u64, data); a test checks this reader against
mcap's on recordings.
"""

from __future__ import annotations

import struct
from collections.abc import Collection, Iterator
from typing import IO, Any

from mcap.data_stream import ReadDataStream
from mcap.records import Chunk
from mcap.stream_reader import get_chunk_data_stream

_MESSAGE = 0x05
_RECORD = struct.Struct("<BQ")
_MESSAGE_HEAD = struct.Struct("<HIQQ")


def iter_raw_messages(
    stream: IO[bytes], summary: Any, channel_ids: Collection[int] | None
) -> Iterator[tuple[int, int, bytes]]:
    """``(channel id, log time ns, data)`` of every message on ``channel_ids`` (all when
    None), in file order. ``summary`` is the file's mcap ``Summary`` (needs its chunk
    indexes)."""
    wanted = None if channel_ids is None else frozenset(channel_ids)
    for index in sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset):
        if wanted is not None and wanted.isdisjoint(index.message_index_offsets):
            continue
        stream.seek(index.chunk_start_offset + 1 + 8)  # past the opcode and length
        chunk = Chunk.read(ReadDataStream(stream))
        data_stream, length = get_chunk_data_stream(chunk)
        data: bytes = data_stream.read(length)
        pos = 0
        end = len(data)
        while pos < end:
            opcode, size = _RECORD.unpack_from(data, pos)
            pos += 9
            if opcode == _MESSAGE:
                channel, _seq, log_time, _publish = _MESSAGE_HEAD.unpack_from(data, pos)
                if wanted is None or channel in wanted:
                    yield channel, log_time, data[pos + 22 : pos + size]
            pos += size
