"""Reading the messages of chosen channels from an indexed MCAP file, fast.

mcap's reader parses every record of every chunk into an object through a byte stream
(``ReadDataStream.read8``...): on the acceptance recording that was a third of a
replay's wall time. This reads each chunk with mcap's own ``Chunk`` record and
decompression (``get_chunk_data_stream``), then walks the uncompressed records with
``struct.unpack_from`` and slices out only the messages of the wanted channels, in file
order. Only chunks whose message index lists a wanted channel are read, and each one is
checked against its CRC (the CRC-32 of its uncompressed records; 0 means none was
written): a chunk that fails it, or does not decompress, raises :class:`ChunkDamageError`
instead of handing on damaged data as recorded (0.3 ms for the acceptance recording).
The MCAP format
is a published spec (records: opcode u8, length u64, content; Message: channel u16,
sequence u32, log time u64, publish time u64, data); a test checks this reader against
mcap's on recordings.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Collection, Iterator
from typing import IO, Any

from mcap.data_stream import ReadDataStream
from mcap.records import Chunk
from mcap.stream_reader import get_chunk_data_stream

from otonav.record.verify import Damage, _one_line

_MESSAGE = 0x05
_RECORD = struct.Struct("<BQ")
_MESSAGE_HEAD = struct.Struct("<HIQQ")


class ChunkDamageError(ValueError):
    """A chunk that fails its CRC or does not decompress."""

    def __init__(self, damage: Damage) -> None:
        super().__init__(damage.describe())
        self.damage = damage


def _damage(index: Any, chunk: Chunk, problem: str) -> Damage:
    return Damage(
        index.chunk_start_offset, problem, chunk.message_start_time, chunk.message_end_time
    )


def iter_raw_messages(
    stream: IO[bytes], summary: Any, channel_ids: Collection[int] | None
) -> Iterator[tuple[int, int, bytes]]:
    """``(channel id, log time ns, data)`` of every message on ``channel_ids`` (all when
    None), in file order. ``summary`` is the file's mcap ``Summary`` (needs its chunk
    indexes). Raises :class:`ChunkDamageError` at the first damaged chunk read."""
    wanted = None if channel_ids is None else frozenset(channel_ids)
    for index in sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset):
        if wanted is not None and wanted.isdisjoint(index.message_index_offsets):
            continue
        stream.seek(index.chunk_start_offset + 1 + 8)  # past the opcode and length
        chunk = Chunk.read(ReadDataStream(stream))
        try:
            data_stream, length = get_chunk_data_stream(chunk)
            data: bytes = data_stream.read(length)
        except Exception as exc:  # zstd/lz4 errors have no common type
            raise ChunkDamageError(
                _damage(index, chunk, f"does not decode ({_one_line(exc)})")
            ) from None
        crc = zlib.crc32(data)
        if chunk.uncompressed_crc not in (0, crc):
            problem = (
                f"CRC mismatch (recorded {chunk.uncompressed_crc:#010x}, computed {crc:#010x})"
            )
            raise ChunkDamageError(_damage(index, chunk, problem))
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
