"""Reading a recording front to back with every chunk checked against its CRC.

A chunk carries the CRC-32 of its uncompressed records. mcap's readers skip that check
by default, and a bit flip in a zstd frame can still decompress: before this module,
``info`` and ``plot`` showed damaged data as if it were recorded, and ``salvage``
copied it under a fresh, valid CRC (issue 17). Here a chunk that does not decompress,
does not match its CRC or does not parse is a :class:`Damage` (where it is, which sim
time it covered, what is wrong) and is skipped; the chunks after it are still read.

A file that ends with the MCAP magic was finished: a record that cannot be read before
its end is damage too, not a cut-off.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

from mcap.exceptions import McapError
from mcap.records import Channel, Chunk, Message, Metadata, Schema
from mcap.stream_reader import CRCValidationError, StreamReader, breakup_chunk

MAGIC = b"\x89MCAP0\r\n"

#: What mcap's readers raise where a file was cut off (a record or its length field
#: ends mid-way: struct.error; a chunk ends early: EndOfFile, an McapError; ...).
CUT_OFF_ERRORS = (McapError, EOFError, ValueError, KeyError, AssertionError, struct.error)

Record = Schema | Channel | Message | Metadata

_CHUNK_FIXED = 9 + 8 + 8 + 8 + 4 + 4 + 8
"""Opcode, record length, start and end time, uncompressed size, CRC, the compression
string's length and the records' length: a chunk record's bytes besides its two
variable parts."""


@dataclass(frozen=True, slots=True)
class Damage:
    """A part of a recording that cannot be trusted."""

    offset: int
    """Byte offset of the damaged record in the file."""
    problem: str
    start_ns: int | None = None
    """First and last log time the chunk says it holds (None: not a chunk)."""
    end_ns: int | None = None

    def describe(self) -> str:
        what = "chunk" if self.start_ns is not None else "record"
        when = (
            f" (sim time {self.start_ns / 1e9:.3f} .. {self.end_ns / 1e9:.3f} s)"
            if self.start_ns is not None and self.end_ns is not None
            else ""
        )
        return f"{what} at byte {self.offset}{when}: {self.problem}"


def describe_damage(path: Path, damage: Sequence[Damage]) -> str:
    """One line: how many damaged parts, the first one, and how many more."""
    chunks = sum(1 for d in damage if d.start_ns is not None)
    others = len(damage) - chunks
    counted = [f"{chunks} damaged chunk{'s' if chunks != 1 else ''}"] if chunks else []
    if others:
        counted.append(f"{others} unreadable record{'s' if others != 1 else ''}")
    more = f"; and {len(damage) - 1} more" if len(damage) > 1 else ""
    return f"{path}: {' and '.join(counted)}: {damage[0].describe()}{more}"


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text if len(text) <= 120 else text[:117] + "..."


def _finished(path: Path) -> bool:
    with path.open("rb") as f:
        size = f.seek(0, 2)
        if size < 2 * len(MAGIC):
            return False
        f.seek(size - len(MAGIC))
        return f.read(len(MAGIC)) == MAGIC


def iter_verified(path: Path, damage: list[Damage]) -> Iterator[Record]:
    """The schema, channel, message and metadata records of ``path`` in file order,
    from every chunk that verifies; each damaged part is appended to ``damage`` and
    skipped. Reading ends at a cut (a cut-off file ends mid-record)."""
    finished = _finished(path)
    with path.open("rb") as f:
        # validate_crcs: the data section's CRC too (schemas, channels and metadata
        # outside the chunks), checked at its end.
        reader = StreamReader(f, emit_chunks=True, validate_crcs=True)
        offset = len(MAGIC)
        try:
            for record in reader.records:
                end = f.tell()
                if isinstance(record, Chunk):
                    start = end - (_CHUNK_FIXED + len(record.compression) + len(record.data))
                    try:
                        # Any failure to decode one chunk (zstd, CRC, a record in it)
                        # is damage to that chunk alone.
                        inner = breakup_chunk(record, validate_crc=True)
                    except Exception as exc:
                        problem = (
                            f"CRC mismatch (recorded {exc.expected:#010x}, "
                            f"computed {exc.actual:#010x})"
                            if isinstance(exc, CRCValidationError)
                            else f"does not decode ({_one_line(exc)})"
                        )
                        first, last = record.message_start_time, record.message_end_time
                        damage.append(Damage(start, problem, first, last))
                    else:
                        for item in inner:
                            if isinstance(item, Schema | Channel | Message | Metadata):
                                yield item
                elif isinstance(record, Schema | Channel | Message | Metadata):
                    yield record
                offset = end
        except CRCValidationError as exc:  # the data section's (a chunk's is caught above)
            if not damage:  # a damaged chunk fails it too: said once is enough
                damage.append(Damage(offset, f"a record outside the chunks: {_one_line(exc)}"))
        except CUT_OFF_ERRORS as exc:
            if finished:  # not a cut: a record in the middle cannot be read
                damage.append(Damage(offset, f"unreadable from here on ({_one_line(exc)})"))
