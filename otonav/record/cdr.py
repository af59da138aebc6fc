"""Fast CDR encoding of otonav messages: the bytes ROS 2 puts on the wire and in bags.

Each message class is compiled once, from its layout (:func:`~otonav.record.schemas.
layout_for`), into a short *plan*: a list of steps that append to a ``bytearray``.
Nested messages are flattened into attribute paths (``header.stamp.sec``), and every
run of fixed-size fields between two variable-size ones (strings, sequences) becomes
one precompiled :class:`struct.Struct` -- Odometry after its two strings is a single
``pack`` of 85 doubles.

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
from collections.abc import Callable
from dataclasses import dataclass
from operator import attrgetter
from typing import Any, Final

from otonav.msgs import Message
from otonav.record.schemas import SEQUENCE, layout_for

__all__ = ("encode",)

Step = Callable[[Any, bytearray], None]
"""One step of a plan: append part of message ``m`` to ``buf``."""

ENCAPSULATION: Final = b"\x00\x01\x00\x00"
"""CDR_LE encapsulation kind (big-endian uint16 1) and options 0."""

_CODES: Final[dict[str, str]] = {
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

_ZEROS: Final = tuple(bytes(n) for n in range(8))
_COUNT: Final = tuple(struct.Struct(f"<{pad}xI").pack for pad in range(4))
"""``_COUNT[pad](n)``: ``pad`` zero bytes then a uint32 -- a string length or a
sequence count, aligned to 4 with ``pad = -len(buf) & 3`` (the header is 4 bytes,
so payload offset and ``len(buf)`` agree modulo 4)."""

_ARRAYS: dict[tuple[str, int], Callable[..., bytes]] = {}
_MAX_ARRAYS: Final = 256


def _array_pack(code: str, n: int) -> Callable[..., bytes]:
    """A cached ``Struct("<{n}{code}").pack`` -- for 360 floats faster than ``array``
    or numpy (2.1 µs vs 5.6 µs vs 6.2 µs, measured)."""
    pack = _ARRAYS.get((code, n))
    if pack is None:
        if len(_ARRAYS) >= _MAX_ARRAYS:
            _ARRAYS.clear()
        pack = _ARRAYS[code, n] = struct.Struct(f"<{n}{code}").pack
    return pack


# -- flattening a layout into leaves ------------------------------------------------


@dataclass(frozen=True, slots=True)
class _Fixed:
    """A primitive (``count`` None) or fixed primitive array at ``path``."""

    path: str
    code: str
    count: int | None


@dataclass(frozen=True, slots=True)
class _Var:
    """A variable-size field: a string, a sequence, or an array of messages/strings."""

    path: str
    kind: str  # "string", "sequence", "strings", "messages", "empty"
    code: str = ""
    count: int = SEQUENCE
    message: type[Message] | None = None


_Leaf = _Fixed | _Var


def _leaves(message: type[Message], prefix: str = "") -> list[_Leaf]:
    """The fields of ``message`` in wire order, nested messages inlined as paths."""
    layout = layout_for(message)
    if not layout.fields:
        return [_Var(prefix, "empty")]
    out: list[_Leaf] = []
    for field in layout.fields:
        path = prefix + field.name
        if not isinstance(field.type, str):
            if field.array is None:
                out += _leaves(field.type, path + ".")
            else:
                out.append(_Var(path, "messages", count=field.array, message=field.type))
        elif field.type == "string":
            if field.array is None:
                out.append(_Var(path, "string"))
            else:
                out.append(_Var(path, "strings", count=field.array))
        elif field.array == SEQUENCE:
            out.append(_Var(path, "sequence", code=_CODES[field.type]))
        else:
            out.append(_Fixed(path, _CODES[field.type], field.array))
    return out


# -- steps ---------------------------------------------------------------------------


def _run_format(run: list[_Fixed], start: int) -> str:
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


Getter = Callable[[Any], Any]


def _segment(path: str, names: list[str], count: int) -> tuple[Getter | None, Getter, int, str]:
    """``(parent getter, value getter, kind, path)`` of one segment of a fixed run; kind
    n > 0: a fixed array of n at ``path``; 0: a tuple of scalars ``names`` of the
    message at ``path``; -1: one scalar."""
    if count:
        return None, attrgetter(path), count, path
    parent = attrgetter(path) if path else None
    if len(names) == 1:
        return parent, attrgetter(names[0]), -1, path
    return parent, attrgetter(*names), 0, path


def _fixed_run_step(run: list[_Fixed]) -> Step:
    """One ``pack`` for a run of fixed-size fields; the padding inside the run depends
    on where it starts, so there is a precompiled Struct per start offset mod 8."""
    packs = tuple(struct.Struct(_run_format(run, start)).pack for start in range(8))
    if all(leaf.count is None for leaf in run):
        if len(run) == 1:
            get_one = attrgetter(run[0].path)

            def scalar(m: Any, buf: bytearray) -> None:
                buf += packs[(len(buf) - 4) & 7](get_one(m))

            return scalar
        get_all = attrgetter(*(leaf.path for leaf in run))

        def scalars(m: Any, buf: bytearray) -> None:
            buf += packs[(len(buf) - 4) & 7](*get_all(m))

        return scalars

    # Fixed arrays among the scalars: gather the values segment by segment. Scalars are
    # grouped by parent message (``pose.pose.position`` -> x, y, z): one walk down the
    # path, then one C-level getter for the group.
    groups: list[tuple[str, list[str], int]] = []
    for leaf in run:
        parent, _, name = leaf.path.rpartition(".")
        if leaf.count is not None:
            groups.append((leaf.path, [], leaf.count))
        elif groups and groups[-1][2] == 0 and groups[-1][0] == parent:
            groups[-1][1].append(name)
        else:
            groups.append((parent, [name], 0))
    segments = [_segment(path, names, count) for path, names, count in groups]

    def mixed(m: Any, buf: bytearray) -> None:
        values: list[Any] = []
        for get_parent, get, count, path in segments:
            part = get(m) if get_parent is None else get(get_parent(m))
            if count == -1:  # one scalar
                values.append(part)
                continue
            if count > 0 and len(part) != count:
                raise ValueError(f"{path}: fixed array of {count}, got {len(part)}")
            values.extend(part)
        buf += packs[(len(buf) - 4) & 7](*values)

    return mixed


def _write_string(buf: bytearray, text: str) -> None:
    """CDR string: uint32 length (aligned to 4) counting the NUL, bytes, NUL."""
    data = text.encode()
    buf += _COUNT[-len(buf) & 3](len(data) + 1)
    buf += data
    buf += b"\x00"


def _string_step(path: str) -> Step:
    get = attrgetter(path)

    def string(m: Any, buf: bytearray) -> None:  # _write_string, inlined: hot path
        data = get(m).encode()
        buf += _COUNT[-len(buf) & 3](len(data) + 1)
        buf += data
        buf += b"\x00"

    return string


def _sequence_step(path: str, code: str) -> Step:
    """A primitive sequence: count, then (only if non-empty) the elements, aligned to
    their size -- after the uint32 count only 8-byte elements can need padding."""
    get = attrgetter(path)
    if struct.calcsize(code) < 8:

        def sequence(m: Any, buf: bytearray) -> None:
            items = get(m)
            n = len(items)
            buf += _COUNT[-len(buf) & 3](n)
            if n:
                buf += _array_pack(code, n)(*items)

        return sequence

    def sequence8(m: Any, buf: bytearray) -> None:
        items = get(m)
        n = len(items)
        buf += _COUNT[-len(buf) & 3](n)
        if n:
            buf += _ZEROS[(4 - len(buf)) & 7]
            buf += _array_pack(code, n)(*items)

    return sequence8


def _count_check(path: str, count: int) -> Callable[[Any, bytearray], None]:
    """Write a sequence's count, or check a fixed array's length (no count on the wire)."""

    def check(items: Any, buf: bytearray) -> None:
        if count == SEQUENCE:
            buf += _COUNT[-len(buf) & 3](len(items))
        elif len(items) != count:
            raise ValueError(f"{path}: fixed array of {count}, got {len(items)}")

    return check


def _strings_step(path: str, count: int) -> Step:
    get, head = attrgetter(path), _count_check(path, count)

    def strings(m: Any, buf: bytearray) -> None:
        items = get(m)
        head(items, buf)
        for text in items:
            _write_string(buf, text)

    return strings


def _messages_step(path: str, message: type[Message], count: int) -> Step:
    """An array of messages: count (if a sequence), then each element's own plan."""
    get, head = attrgetter(path), _count_check(path, count)

    def messages(m: Any, buf: bytearray) -> None:
        items = get(m)
        head(items, buf)
        steps = _plan(message)
        for item in items:
            for step in steps:
                step(item, buf)

    return messages


def _empty_step(m: Any, buf: bytearray) -> None:
    """A message with no fields: one uint8 0, as rosidl adds to satisfy IDL."""
    buf += b"\x00"


def _var_step(leaf: _Var) -> Step:
    if leaf.kind == "string":
        return _string_step(leaf.path)
    if leaf.kind == "sequence":
        return _sequence_step(leaf.path, leaf.code)
    if leaf.kind == "strings":
        return _strings_step(leaf.path, leaf.count)
    if leaf.kind == "messages":
        assert leaf.message is not None
        return _messages_step(leaf.path, leaf.message, leaf.count)
    return _empty_step


# -- plans ---------------------------------------------------------------------------

_PLANS: dict[type[Message], tuple[Step, ...]] = {}


def _compile(message: type[Message]) -> tuple[Step, ...]:
    """Group the leaves: each run of fixed-size leaves -> one step, others -> a step."""
    steps: list[Step] = []
    run: list[_Fixed] = []
    for leaf in _leaves(message):
        if isinstance(leaf, _Fixed):
            run.append(leaf)
            continue
        if run:
            steps.append(_fixed_run_step(run))
            run = []
        steps.append(_var_step(leaf))
    if run:
        steps.append(_fixed_run_step(run))
    return tuple(steps)


def _plan(message: type[Message]) -> tuple[Step, ...]:
    steps = _PLANS.get(message)
    if steps is None:
        steps = _PLANS[message] = _compile(message)
    return steps


def encode(message: Message) -> bytes:
    """The CDR bytes (with encapsulation header) of ``message``, as ROS 2 would write
    them for its ``ros_type``. Raises ValueError for a value the ROS type cannot hold
    (out-of-range integer, wrong fixed-array length, float too large for float32)."""
    steps = _PLANS.get(type(message)) or _plan(type(message))
    buf = bytearray(ENCAPSULATION)
    try:
        for step in steps:
            step(message, buf)
    except (struct.error, OverflowError) as error:
        raise ValueError(f"cannot encode {message.ros_type}: {error}") from error
    return bytes(buf)
