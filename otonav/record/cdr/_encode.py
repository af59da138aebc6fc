"""Fast CDR encoding of otonav messages: the bytes ROS 2 puts on the wire and in bags.

Each message class is compiled once, from its layout (:func:`~otonav.record._schemas.
layout_for`), into one generated Python function (:class:`_Source`; read it in the
function's ``__doc__``). Nested messages are flattened into attribute paths
(``header.stamp.sec``), each nested message is read once into a local, and every run of
fixed-size fields between two variable-size ones (strings, sequences) becomes one
precompiled :class:`struct.Struct` -- Odometry after its two strings is a single
``pack`` of 85 doubles, /clock one ``pack`` of two integers. The generated code follows
the same rules as the step-per-run plan it replaced (ADR 0025): the bytes are the same.

The CDR rules are :mod:`otonav.record.cdr._layout`'s.
"""

from __future__ import annotations

import struct
from collections.abc import Callable
from operator import attrgetter
from typing import Any, Final

from otonav.msgs import Message
from otonav.msgs._flat import FlatLayout, flat_state, materialize, real_type
from otonav.record._schemas import SEQUENCE
from otonav.record.cdr._layout import (
    ENCAPSULATION,
    Fixed,
    Var,
    field_offsets,
    flatten,
    run_format,
    wire_parts,
)

__all__ = ("encode",)

Step = Callable[[Any, bytearray], None]
"""One step of a plan: append part of message ``m`` to ``buf``."""


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


# -- steps ---------------------------------------------------------------------------


def _write_string(buf: bytearray, text: str) -> None:
    """CDR string: uint32 length (aligned to 4) counting the NUL, bytes, NUL."""
    data = text.encode()
    buf += _COUNT[-len(buf) & 3](len(data) + 1)
    buf += data
    buf += b"\x00"


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


def _var_step(leaf: Var) -> Step:
    """The step of a variable-size field other than a string (strings are generated
    inline, :class:`_Source`)."""
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


class _Source:
    """The source of one message type's generated encoder, built leaf by leaf."""

    def __init__(self, *, top_level: bool) -> None:
        self.lines: list[str] = []
        self.names: dict[str, object] = {"_COUNT": _COUNT, "ValueError": ValueError}
        self.locals: dict[str, str] = {"": "m"}
        self.offset: int | None = 0 if top_level else None
        """Payload offset mod 8 while it is known statically: from the start of a
        top-level message until its first variable-size field. Otherwise (and always
        for an element of an array) the packs are picked by ``len(buf)`` at run time."""

    def name(self, value: object, prefix: str) -> str:
        key = f"{prefix}{len(self.names)}"
        self.names[key] = value
        return key

    def ref(self, path: str) -> str:
        """An expression for the value at ``path`` of ``m``; each nested message on the
        way is read once into a local."""
        parent, _, attr = path.rpartition(".")
        if parent not in self.locals:
            self.locals[parent] = f"_v{len(self.locals)}"
            self.lines.append(f"{self.locals[parent]} = {self.ref(parent)}")
        return f"{self.locals[parent]}.{attr}"

    def fixed_run(self, run: list[Fixed]) -> None:
        """One pack for the run; fixed arrays are length-checked and spliced in."""
        args: list[str] = []
        for leaf in run:
            if leaf.count is None:
                args.append(self.ref(leaf.path))
                continue
            array = f"_a{len(self.lines)}"
            self.lines.append(f"{array} = {self.ref(leaf.path)}")
            self.lines.append(
                f"if len({array}) != {leaf.count}: raise ValueError("
                f"'{leaf.path}: fixed array of {leaf.count}, got %d' % len({array}))"
            )
            args.append(f"*{array}")
        if self.offset is not None:
            packer = struct.Struct(run_format(run, self.offset))
            pack = self.name(packer.pack, "_p")
            self.lines.append(f"buf += {pack}({', '.join(args)})")
            self.offset = (self.offset + packer.size) & 7
            return
        packs = tuple(struct.Struct(run_format(run, start)).pack for start in range(8))
        table = self.name(packs, "_P")
        self.lines.append(f"buf += {table}[(len(buf) - 4) & 7]({', '.join(args)})")

    def string(self, path: str) -> None:
        count = "_COUNT[-len(buf) & 3]" if self.offset is None else f"_COUNT[{-self.offset & 3}]"
        text = f"_s{len(self.lines)}"
        self.lines.append(f"{text} = {self.ref(path)}.encode()")
        self.lines.append(f"buf += {count}(len({text}) + 1)")
        self.lines.append(f"buf += {text}")
        self.lines.append("buf += b'\\x00'")
        self.offset = None

    def var(self, leaf: Var) -> None:
        if leaf.kind == "messages":
            assert leaf.message is not None
            items = f"_a{len(self.lines)}"
            self.lines.append(f"{items} = {self.ref(leaf.path)}")
            self.lines.append(
                f"{self.name(_count_check(leaf.path, leaf.count), '_head')}({items}, buf)"
            )
            element = self.name(_plan(leaf.message)[0], "_encode")
            self.lines.append(f"for _item in {items}: {element}(_item, buf)")
        else:
            self.lines.append(f"{self.name(_var_step(leaf), '_step')}(m, buf)")
        self.offset = None

    def compile(self, message: type[Message]) -> Step:
        body = "\n".join(f"    {line}" for line in self.lines) or "    pass"
        source = f"def encode_{message.__name__}(m, buf):\n{body}\n"
        namespace = dict(self.names)
        exec(compile(source, f"<cdr encoder of {message.__name__}>", "exec"), namespace)
        step: Step = namespace[f"encode_{message.__name__}"]  # type: ignore[assignment]
        step.__doc__ = source
        return step


def _compile(message: type[Message], *, top_level: bool) -> Step:
    """One generated function per message type: every field of the flattened layout in
    wire order, nested messages read once into locals, each run of fixed-size fields
    one precompiled ``Struct.pack`` (its padding resolved at compile time while the
    offset is known, else picked by offset mod 8), strings inline. Sequences and arrays
    of messages call their step (an element type has its own generated function).
    Measured against the step-per-run plan it replaces: Odometry 6.0 -> 3.3 us."""
    source = _Source(top_level=top_level)
    for part in wire_parts(flatten(message)):
        if isinstance(part, list):
            source.fixed_run(part)
        elif part.kind == "string":
            source.string(part.path)
        else:
            source.var(part)
    return source.compile(message)


_TOP: dict[type[Message], Step] = {}


def _plan(message: type[Message]) -> tuple[Step, ...]:
    """The steps of ``message`` anywhere in a buffer (an element of an array)."""
    steps = _PLANS.get(message)
    if steps is None:
        steps = _PLANS[message] = (_compile(message, top_level=False),)
    return steps


def _top(message: type[Message]) -> Step:
    """The encoder of ``message`` right after the encapsulation header."""
    step = _TOP.get(message)
    if step is None:
        step = _TOP[message] = _compile(message, top_level=True)
    return step


def encode(message: Message) -> bytes:
    """The CDR bytes (with encapsulation header) of ``message``, as ROS 2 would write
    them for its ``ros_type``. Raises ValueError for a value the ROS type cannot hold
    (out-of-range integer, wrong fixed-array length, float too large for float32)."""
    step = _TOP.get(type(message))
    if step is None:
        flat = flat_state(message)
        if flat is not None:  # a flat message (never in _TOP): its layout's one pack
            layout, values = flat
            try:
                return (layout.cdr or _flat_packer(layout))(*values)
            except (struct.error, OverflowError) as error:
                raise ValueError(f"cannot encode {message.ros_type}: {error}") from error
        step = _top(real_type(type(message)))
    buf = bytearray(ENCAPSULATION)
    try:
        step(message, buf)
    except (struct.error, OverflowError) as error:
        raise ValueError(f"cannot encode {message.ros_type}: {error}") from error
    return bytes(buf)


# -- fixed layouts ---------------------------------------------------------------------


def _flat_packer(layout: FlatLayout[Any]) -> Callable[..., bytes]:
    """The CDR encoder of ``layout``'s messages: the template's bytes with the values
    packed in place, as one precompiled ``Struct`` whose constant stretches are ``s``
    items (the template's own bytes, padding included). Checked once against the
    field-by-field encoder with a distinct value in every varying field; cached on the
    layout (``layout.cdr``). An Odometry: 2.25 us field by field, ~0.6 us this way."""
    template = encode(layout.template)
    offsets, end = field_offsets(layout.template)
    if end + len(ENCAPSULATION) != len(template):
        raise AssertionError(
            f"{layout}: walked {end} payload bytes, the encoder wrote {len(template) - 4}"
        )
    for path in layout.paths:
        if path not in offsets:  # a tuple of small ints whose ROS type is not bytes
            raise ValueError(
                f"{layout}: '{path}' is not a primitive of {layout.message_type.ros_type}; "
                "an array given as bytes must be a uint8 (byte, char) array"
            )
    places = sorted(
        (len(ENCAPSULATION) + offsets[path][0], offsets[path][1], i)
        for i, path in enumerate(layout.paths)
    )
    fmt, pos = "<", 0
    args: list[str] = []
    names: dict[str, object] = {}
    for at, code, i in places:
        if at > pos:
            name = f"_c{len(names)}"
            names[name] = template[pos:at]
            fmt += f"{at - pos}s"
            args.append(name)
        fmt += code
        args.append(f"v{i}")
        pos = at + struct.calcsize(code)
    if pos < len(template):
        names[f"_c{len(names)}"] = template[pos:]
        fmt += f"{len(template) - pos}s"
        args.append(f"_c{len(names) - 1}")
    names["_pack"] = struct.Struct(fmt).pack
    params = ", ".join(f"v{i}" for i in range(len(layout.paths)))
    source = (
        f"def pack_{layout.message_type.__name__}({params}):\n    return _pack({', '.join(args)})\n"
    )
    exec(compile(source, f"<cdr packer of {layout!r}>", "exec"), names)
    pack: Callable[..., bytes] = names[f"pack_{layout.message_type.__name__}"]  # type: ignore[assignment]
    pack.__doc__ = f"{source}\nformat {fmt}"
    probe = tuple(_probe(code, i) for _at, code, i in sorted(places, key=lambda p: p[2]))
    if pack(*probe) != encode(materialize(layout(*probe))):
        raise AssertionError(f"{layout}: the fixed-layout packer disagrees with the encoder")
    layout.cdr = pack
    return pack


def _probe(code: str, i: int) -> object:
    """A value for a field of struct ``code``, distinct for each ``i`` (the check of
    :func:`_flat_packer`)."""
    if code.endswith("s"):  # an array of bytes: distinct values in each element
        return bytes((i + 1 + k) % 256 for k in range(struct.calcsize(code)))
    if code in "fd":
        return 1.0 + 0.25 * i
    if code == "?":
        return i % 2 == 0
    return 1 + i % 100
