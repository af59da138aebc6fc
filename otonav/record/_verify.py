"""Reading a recording front to back with every chunk checked against its CRC.

A chunk carries the CRC-32 of its uncompressed records. mcap's readers skip that check
by default, and a bit flip in a zstd frame can still decompress: before this module,
``info`` and ``plot`` showed damaged data as if it were recorded, and ``salvage``
copied it under a fresh, valid CRC (issue 17). Here a chunk that does not decompress,
does not match its CRC or does not parse is a :class:`Damage` (where it is, which sim
time it covered, what is wrong) and is skipped; the chunks after it are still read.

A file that ends with the MCAP magic was finished: a record that cannot be read before
its end is damage too, not a cut-off (issue 41: it is skipped by its length when a record
follows there), and so is an index (the summary section) that fails its CRC.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Generator, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from mcap.exceptions import McapError
from mcap.records import Channel, Chunk, DataEnd, Message, Metadata, Schema
from mcap.stream_reader import CRCValidationError, StreamReader, breakup_chunk
from mcap.writer import MCAP0_MAGIC as MAGIC

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
    """The schema, channel, message and metadata records of ``path``'s data section in
    file order, from every chunk that verifies; each damaged part is appended to
    ``damage`` and skipped. Reading ends at a cut (a cut-off file ends mid-record) and at
    the end of the data section (the summary after it repeats schemas and channels and
    indexes the rest; :func:`summary_damage` checks it). In a finished file a record that
    does not parse is skipped by its length when a record follows it there."""
    finished = _finished(path)
    with path.open("rb") as f:
        size = f.seek(0, 2)
        f.seek(0)  # the first reader reads the magic
        resume: int | None = len(MAGIC)
        first = True
        while resume is not None:
            resume = yield from _verified_from(f, resume, first, finished, size, damage)
            first = False
            if resume is not None:
                f.seek(resume)


def _verified_from(
    f: BinaryIO, offset: int, first: bool, finished: bool, size: int, damage: list[Damage]
) -> Generator[Record, None, int | None]:
    """:func:`iter_verified` from ``offset``; where to resume after a record that does
    not parse (None: the end)."""
    # validate_crcs: the data section's CRC too (schemas, channels and metadata outside
    # the chunks), checked at its end; from the start of the file only.
    reader = StreamReader(
        f, skip_magic=not first, emit_chunks=True, validate_crcs=first, record_size_limit=size
    )
    try:
        for record in reader.records:
            end = f.tell()
            if isinstance(record, DataEnd):
                return None
            if isinstance(record, Chunk):
                start = end - (_CHUNK_FIXED + len(record.compression) + len(record.data))
                try:
                    # Any failure to decode one chunk (zstd, CRC, a record in it)
                    # is damage to that chunk alone.
                    inner = breakup_chunk(record, validate_crc=True)
                except Exception as exc:
                    problem = (
                        f"CRC mismatch (recorded {exc.expected:#010x}, computed {exc.actual:#010x})"
                        if isinstance(exc, CRCValidationError)
                        else f"does not decode ({_one_line(exc)})"
                    )
                    first_ns, last_ns = record.message_start_time, record.message_end_time
                    damage.append(Damage(start, problem, first_ns, last_ns))
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
    except (*CUT_OFF_ERRORS, MemoryError) as exc:  # MemoryError: a length field flipped
        if finished:  # not a cut: a record in the middle cannot be read
            after = _next_record(f, offset, size)
            said = "skipped" if after is not None else "unreadable from here on"
            damage.append(Damage(offset, f"{said} ({_one_line(exc)})"))
            return after
    return None


def _next_record(f: BinaryIO, offset: int, size: int) -> int | None:
    """Where the record after the one at ``offset`` starts, if its length field leads to
    the opcode of another record before the end of the file (else None)."""
    f.seek(offset)
    head = f.read(9)
    if len(head) < 9 or not _OPCODES[0] <= head[0] <= _OPCODES[1]:
        return None
    after = offset + 9 + int.from_bytes(head[1:], "little")
    if after >= size - len(MAGIC):
        return None
    f.seek(after)
    opcode = f.read(1)
    return after if opcode and _OPCODES[0] <= opcode[0] <= _OPCODES[1] else None


_OPCODES = (0x01, 0x0F)
"""MCAP's record opcodes: Header .. DataEnd."""


def summary_start(path: Path) -> int | None:
    """Where the summary section (the index) starts, as the footer says (None: no
    plausible footer)."""
    with path.open("rb") as f:
        footer = f.seek(0, 2) - len(MAGIC) - _FOOTER_FIELDS
        if footer < len(MAGIC):
            return None
        f.seek(footer)
        (start,) = struct.unpack("<Q", f.read(8))
    return start if len(MAGIC) <= start < footer else None


def summary_damage(path: Path) -> Damage | None:
    """The summary section (the index) when it fails the CRC the footer holds for it."""
    start = summary_start(path)
    if start is None:
        return None
    with path.open("rb") as f:
        footer = f.seek(0, 2) - len(MAGIC) - _FOOTER_FIELDS
        f.seek(footer + 16)
        (crc,) = struct.unpack("<I", f.read(4))
        f.seek(start)
        computed = zlib.crc32(f.read(footer + 16 - start))
    if crc == 0 or computed == crc:
        return None
    return Damage(
        start,
        f"the index (summary section) fails its CRC (recorded {crc:#010x}, computed "
        f"{computed:#010x}): read front to back instead",
    )


_FOOTER_FIELDS = 8 + 8 + 4
"""The footer's summary start, summary offset start and summary CRC."""
