"""The CDR layout both directions share: the wire rules, and a message class flattened
into leaves (fixed runs and variable-size fields) at their payload offsets.

The CDR rules implemented (plain CDR / XCDR1, little endian, as Fast-CDR writes it):

* a 4-byte encapsulation header ``00 01 00 00`` (CDR_LE, options 0); alignment is
  counted from the end of it, i.e. from the start of the payload;
* a primitive is aligned to its own size (1, 2, 4 or 8 bytes), padding is zeros;
* a nested message adds nothing of its own: its fields follow inline; a message with
  no fields is one ``uint8`` 0 (rosidl's ``structure_needs_at_least_one_member``);
* a string is a ``uint32`` byte length including the NUL, the UTF-8 bytes, a NUL;
* a sequence ``T[]`` is a ``uint32`` count, then the elements; an empty sequence is
  the count alone (elements, not the sequence, carry the alignment);
* a fixed array ``T[n]`` is the n elements with no count.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Final

from otonav.msgs import Message
from otonav.msgs._flat import real_type
from otonav.record._schemas import SEQUENCE, layout_for

ENCAPSULATION: Final = b"\x00\x01\x00\x00"
"""CDR_LE encapsulation kind (big-endian uint16 1) and options 0."""


CODES: Final[dict[str, str]] = {
    "bool": "?",
    "byte": "B",
    "char": "B",  # ROS 2 maps char to uint8
    "int8": "b",
    "uint8": "B",
    "int16": "h",
    "uint16": "H",
    "int32": "i",
    "uint32": "I",
    "int64": "q",
    "uint64": "Q",
    "float32": "f",
    "float64": "d",
}
"""ROS primitive -> struct format code (size = CDR alignment)."""


@dataclass(frozen=True, slots=True)
class Fixed:
    """A primitive (``count`` None) or fixed primitive array at ``path``."""

    path: str
    code: str
    count: int | None


@dataclass(frozen=True, slots=True)
class Var:
    """A variable-size field: a string, a sequence, or an array of messages/strings."""

    path: str
    kind: str  # "string", "sequence", "strings", "messages", "empty"
    code: str = ""
    count: int = SEQUENCE
    message: type[Message] | None = None


Leaf = Fixed | Var


def wire_parts(leaves: Sequence[Leaf]) -> Iterator[list[Fixed] | Var]:
    """``leaves`` in wire order, each run of fixed-size fields between two variable-size
    ones gathered into one list (one struct each, in both directions)."""
    run: list[Fixed] = []
    for leaf in leaves:
        if isinstance(leaf, Fixed):
            run.append(leaf)
            continue
        if run:
            yield run
            run = []
        yield leaf
    if run:
        yield run


def flatten(message: type[Message], prefix: str = "") -> list[Leaf]:
    """The fields of ``message`` in wire order, nested messages inlined as paths."""
    layout = layout_for(message)
    if not layout.fields:
        return [Var(prefix, "empty")]
    out: list[Leaf] = []
    for field in layout.fields:
        path = prefix + field.name
        if not isinstance(field.type, str):
            if field.array is None:
                out += flatten(field.type, path + ".")
            else:
                out.append(Var(path, "messages", count=field.array, message=field.type))
        elif field.type == "string":
            if field.array is None:
                out.append(Var(path, "string"))
            else:
                out.append(Var(path, "strings", count=field.array))
        elif field.array == SEQUENCE:
            out.append(Var(path, "sequence", code=CODES[field.type]))
        else:
            out.append(Fixed(path, CODES[field.type], field.array))
    return out


def run_format(run: list[Fixed], start: int) -> str:
    """The struct format of ``run`` starting at payload offset ``start`` (mod 8), with
    explicit ``x`` padding so each primitive lands on a multiple of its size."""
    fmt, offset = "<", start
    for leaf in run:
        size = struct.calcsize(leaf.code)
        pad = -offset % size
        count = 1 if leaf.count is None else leaf.count
        fmt += f"{pad}x{count}{leaf.code}"
        offset += pad + size * count
    return fmt


def field_offsets(
    message: Message, prefix: str = "", offset: int = 0
) -> tuple[dict[str, tuple[int, str]], int]:
    """Where each scalar primitive of ``message`` lands (payload offset, struct code),
    by path, and the offset after it: the CDR rules of the module docstring walked over
    one message's values (its strings and sequences have the lengths they have). The
    elements of primitive arrays too (``data.3``), and an array of ``uint8`` (or
    ``byte``, ``char``) of n elements also as a whole (``data``, code ``{n}s``)."""
    found: dict[str, tuple[int, str]] = {}
    layout = layout_for(real_type(type(message)))
    if not layout.fields:
        return found, offset + 1
    for field in layout.fields:
        path = prefix + field.name
        value = getattr(message, field.name)
        if field.array is not None and field.array == SEQUENCE:
            offset += -offset % 4 + 4  # the count
        if not isinstance(field.type, str):
            for i, item in enumerate((value,) if field.array is None else value):
                where = f"{path}." if field.array is None else f"{path}.{i}."
                inner, offset = field_offsets(item, where, offset)
                found.update(inner)
        elif field.type == "string":
            for text in (value,) if field.array is None else value:
                offset += -offset % 4 + 4 + len(text.encode()) + 1
        else:
            code = CODES[field.type]
            size = struct.calcsize(code)
            count = 1 if field.array is None else len(value)
            if count:
                offset += -offset % size
            if field.array is None:
                found[path] = (offset, code)
            else:  # each element; an array of bytes also whole, as one bytes item
                for i in range(count):
                    found[f"{path}.{i}"] = (offset + size * i, code)
                if code == "B":
                    found[path] = (offset, f"{count}s")
            offset += size * count
    return found, offset
