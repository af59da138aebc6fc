"""CDR decoding back into otonav messages: the inverse of :mod:`otonav.record.cdr._encode`.

Replay feeds recorded messages to actors, so it needs the same pydantic objects the
stack published, bit for bit (a float64 comes back as the same double, a float32 scan
range as the same float32 value). The decoder is compiled per message class from the
same layouts (:func:`~otonav.record._schemas.layout_for`) and the same leaf flattening as
the encoder: each run of fixed-size fields is one precompiled ``unpack_from`` (one per
start offset mod 8, since the padding inside a run depends on where it starts);
strings and sequences are read one by one; then the values are built back into the
nested messages as ``Message.fast`` builds them, all in one straight-line function
generated per class (:func:`_compile_decoder`). ``decode(type(m), encode(m)) == m`` for every
message (a property test), and the values agree with ``mcap_ros2``'s generic decoder on
recordings (a test), which is the independent oracle.

Only little-endian plain CDR (what ROS 2 writes and what we record) is read; anything
else is a ``ValueError`` naming the type.
"""

from __future__ import annotations

import functools
import struct
from collections.abc import Callable
from typing import Any, Final, TypeVar

from otonav.msgs import Header, Message
from otonav.msgs._base import _new, _setstate
from otonav.msgs._flat import FlatLayout
from otonav.record._schemas import SEQUENCE, layout_for
from otonav.record.cdr._encode import encode
from otonav.record.cdr._layout import (
    ENCAPSULATION,
    Fixed,
    Var,
    field_offsets,
    flatten,
    run_format,
    wire_parts,
)

__all__ = ("decode", "flat_values")

M = TypeVar("M", bound=Message)

ReadStep = Callable[[bytes, int, list[Any]], int]
"""Read one part of a message from ``data`` at ``pos``, append its value(s), return
the new position (``pos`` counts the 4-byte encapsulation header)."""

_U32: Final = struct.Struct("<I")


def _aligned(pos: int, size: int) -> int:
    """``pos`` moved up to a multiple of ``size`` counted from the payload start."""
    return pos + (-(pos - 4) % size)


def _read_string(data: bytes, pos: int) -> tuple[str, int]:
    pos = _aligned(pos, 4)
    (length,) = _U32.unpack_from(data, pos)
    pos += 4
    if length == 0:  # not what ROS writes, but an empty string is the only reading
        return "", pos
    end = pos + length
    if end > len(data):
        raise ValueError("string runs past the end of the message")
    return data[pos : end - 1].decode(), end


def _count(data: bytes, pos: int, count: int) -> tuple[int, int]:
    """A sequence's element count (read) or a fixed array's (known)."""
    if count != SEQUENCE:
        return count, pos
    pos = _aligned(pos, 4)
    (n,) = _U32.unpack_from(data, pos)
    return n, pos + 4


def _sequence(code: str, count: int) -> ReadStep:
    size = struct.calcsize(code)

    def read(data: bytes, pos: int, out: list[Any]) -> int:
        n, pos = _count(data, pos, count)
        if not n:
            out.append(())
            return pos
        pos = _aligned(pos, size)
        out.append(struct.unpack_from(f"<{n}{code}", data, pos))
        return pos + n * size

    return read


def _strings(count: int) -> ReadStep:
    def read(data: bytes, pos: int, out: list[Any]) -> int:
        n, pos = _count(data, pos, count)
        items = []
        for _ in range(n):
            text, pos = _read_string(data, pos)
            items.append(text)
        out.append(tuple(items))
        return pos

    return read


def _messages(message: type[Message], count: int) -> ReadStep:
    def read(data: bytes, pos: int, out: list[Any]) -> int:
        n, pos = _count(data, pos, count)
        decode_one = _decoder(message)
        items = []
        for _ in range(n):
            item, pos = decode_one(data, None, pos)
            items.append(item)
        out.append(tuple(items))
        return pos

    return read


def _empty(data: bytes, pos: int, out: list[Any]) -> int:
    out.append(None)  # the one uint8 rosidl adds to a message with no fields
    return pos + 1


def _var(leaf: Var) -> ReadStep:
    """The read step of a variable part other than a string (read inline)."""
    if leaf.kind == "sequence":
        return _sequence(leaf.code, SEQUENCE)
    if leaf.kind == "strings":
        return _strings(leaf.count)
    if leaf.kind == "messages":
        assert leaf.message is not None
        return _messages(leaf.message, leaf.count)
    return _empty


Decoder = Callable[..., tuple[Any, int]]
"""``(data, header=None, pos=4)``: decode one message from CDR ``data`` (with its
encapsulation header) at ``pos`` (and, for a stamped message, its Header if already
decoded); returns it and where it ended."""


def _compile_decoder(message: type[Message]) -> Decoder:
    """One generated function per class, straight-line: each fixed run one
    ``unpack_from`` into a tuple, each string read inline, the other variable parts
    through their read steps; then every message built bottom-up as
    ``otonav.msgs._base.make`` builds one (inlined), no flat list: an Odometry 6.3 -> 5.0 us, a
    360-beam LaserScan 6.5 -> 5.9 us (the navigator's replay decodes ~860 inputs). An
    element of an array of messages is read by its own class's decoder from where it
    starts (``pos``). ``tests/unit/record/test_cdr.py`` checks every message type, and
    strings of every length mod 4 before each field, against the original."""
    names: dict[str, object] = {"_new": _new, "_ss": _setstate, "_U32": _U32, "_len": len}
    lines: list[str] = []
    values: list[str] = []  # flat value index -> its expression
    runs: dict[int, tuple[str, int]] = {}  # flat index -> (run tuple name, index in it)

    def read_run(run: list[Fixed]) -> None:
        k = len([n for n in names if n.startswith("_S")])
        structs = tuple(struct.Struct(run_format(run, start)) for start in range(8))
        names[f"_S{k}"] = structs
        lines.append(f"u = _S{k}[(pos - 4) & 7]")
        lines.append(f"t{k} = u.unpack_from(data, pos)")
        lines.append("pos += u.size")
        at = 0
        for leaf in run:
            for _ in range(1 if leaf.count is None else leaf.count):
                runs[len(values)] = (f"t{k}", at)
                values.append(f"t{k}[{at}]")
                at += 1

    leaves = flatten(message)
    stamped = _stamped(message)
    if stamped:
        # Its header comes first, where a Header alone would be: decoded by the Header
        # decoder, or given (a lazy replay input decodes its header alone first).
        assert [leaf.path for leaf in leaves[:3]] == [*_HEADER_PATHS]
        leaves = leaves[3:]
        names["_header"] = _decoder(Header)
        names["_past_header"] = _past_header
        lines += [
            "if header is None:",
            "    header, pos = _header(data, None, pos)",
            "else:",
            "    pos = _past_header(data)",
        ]
    for leaf in wire_parts(leaves):
        if isinstance(leaf, list):
            read_run(leaf)
            continue
        v = f"v{len(values)}"
        if leaf.kind == "string":
            lines += [
                "pos += -(pos - 4) & 3",
                "(n,) = _U32.unpack_from(data, pos)",
                "pos += 4",
                "if n:",
                "    end = pos + n",
                "    if end > _len(data):",
                "        raise ValueError('string runs past the end of the message')",
                f"    {v} = data[pos : end - 1].decode()",
                "    pos = end",
                "else:",
                f"    {v} = ''",
            ]
        else:
            step = f"_r{len(values)}"
            names[step] = _var(leaf)
            lines += ["out = []", f"pos = {step}(data, pos, out)", f"{v} = out[0]"]
        values.append(v)

    made = 0

    def build(current: type[Message], i: int) -> tuple[str, int]:
        """Lines that make a ``current`` from the flat values at ``i``; its name."""
        nonlocal made
        made += 1
        name = f"m{made}"
        cls = f"_c{made}"
        names[cls] = current
        names[cls + "_fields"] = current._otonav_fields
        layout = layout_for(current)
        parts = []
        if not layout.fields:
            i += 1
        for k, field in enumerate(layout.fields):
            if k == 0 and stamped and current is message:
                code = "header"
            elif not isinstance(field.type, str) and field.array is None:
                code, i = build(field.type, i)
            elif isinstance(field.type, str) and field.type != "string" and (field.array or 0) > 0:
                n = field.array or 0
                (tup, at), (tup_end, at_end) = runs[i], runs[i + n - 1]
                assert tup == tup_end, "an array lies in one run"
                assert at_end == at + n - 1
                code, i = f"{tup}[{at}:{at + n}]", i + n
            else:  # one value: a scalar, a string, a sequence, an array of messages/strings
                code, i = values[i], i + 1
            parts.append(f"{field.name!r}: {code}")
        lines.extend(  # make(), inlined
            [
                f"{name} = _new({cls})",
                f"_ss({name}, {{'__dict__': {{{', '.join(parts)}}}, '__pydantic_fields_set__': "
                f"{cls}_fields, '__pydantic_extra__': None, '__pydantic_private__': None}})",
            ]
        )
        return name, i

    top, used = build(message, 0)
    assert used == len(values)
    # The reads (in wire order), then the builds (innermost messages first).
    body = "\n".join("    " + line for line in lines)
    source = (
        f"def decode_{message.__name__}(data, header=None, pos=4):\n{body}\n    return {top}, pos\n"
    )
    exec(compile(source, f"<cdr decoder of {message.__name__}>", "exec"), names)
    decoder: Decoder = names[f"decode_{message.__name__}"]  # type: ignore[assignment]
    return decoder


_DECODERS: dict[type[Message], Decoder] = {}
_HEADER_PATHS = ("header.stamp.sec", "header.stamp.nanosec", "header.frame_id")


def _decoder(message: type[Message]) -> Decoder:
    decoder = _DECODERS.get(message)
    if decoder is None:
        decoder = _DECODERS[message] = _compile_decoder(message)
    return decoder


def _stamped(message: type[Message]) -> bool:
    """Whether ``message``'s first field is a std_msgs Header."""
    fields = layout_for(message).fields
    return bool(fields) and fields[0].name == "header" and fields[0].type is Header


def _past_header(data: bytes) -> int:
    """Where the field after a leading Header starts: past its stamp (8 bytes) and its
    frame_id (a uint32 length, aligned already, then the bytes)."""
    length: int = _U32.unpack_from(data, 12)[0]
    return 16 + length


def decode(message: type[M], data: bytes, header: Header | None = None) -> M:
    """The ``message`` encoded in ``data`` (CDR with its encapsulation header).

    ``header``: for a message whose first field is a Header, that Header already
    decoded from ``data`` (``decode(Header, data)``): it is used as is.

    Raises ValueError for data that is not little-endian CDR of that type (too short,
    a string past the end, trailing garbage is tolerated as ROS 2 pads to 4 bytes).
    """
    if not data.startswith(ENCAPSULATION):
        raise ValueError(
            f"cannot decode {message.ros_type}: not little-endian plain CDR "
            f"(encapsulation {bytes(data[:4]).hex() or 'missing'}, expected {ENCAPSULATION.hex()})"
        )
    decoder = _DECODERS.get(message) or _decoder(message)
    try:
        result, pos = decoder(data, header)
    except (struct.error, UnicodeDecodeError) as error:
        raise ValueError(f"cannot decode {message.ros_type}: {error}") from error
    if pos > len(data):
        raise ValueError(f"cannot decode {message.ros_type}: the data ends early")
    return result  # type: ignore[no-any-return]


@functools.cache  # layouts are module constants: compiled once per process
def flat_values(layout: FlatLayout[Any]) -> Callable[[bytes], tuple[Any, ...] | None]:
    """The inverse of a fixed layout's packer (:mod:`otonav.msgs._flat`): from CDR bytes,
    the values at ``layout.paths`` when everything else is the template's, byte for byte
    (so ``layout(*values)`` is the message the bytes hold, and encodes to them); None
    otherwise (another length, a frame id, a covariance, a -0.0 where the template has
    0.0...). One precompiled ``unpack`` and a comparison per constant stretch: ~0.6 us
    for an Odometry, against ~5 us to decode it."""
    template = encode(layout.template)
    offsets, _end = field_offsets(layout.template)
    places = sorted(
        (len(ENCAPSULATION) + offsets[path][0], offsets[path][1], i)
        for i, path in enumerate(layout.paths)
    )
    fmt, pos = "<", 0
    constants: list[tuple[int, bytes]] = []  # (index in the unpacked tuple, bytes)
    order: dict[int, int] = {}  # path index -> index in the unpacked tuple
    items = 0
    for at, code, i in places:
        if at > pos:
            constants.append((items, template[pos:at]))
            fmt += f"{at - pos}s"
            items += 1
        fmt += code
        order[i] = items
        items += 1
        pos = at + struct.calcsize(code)
    if pos < len(template):
        constants.append((items, template[pos:]))
        fmt += f"{len(template) - pos}s"
    unpack = struct.Struct(fmt)
    names: dict[str, object] = {"_unpack": unpack.unpack, "_size": unpack.size, "_len": len}
    checks = []
    for k, (index, chunk) in enumerate(constants):
        names[f"_c{k}"] = chunk
        checks.append(f"r[{index}] != _c{k}")
    picked = ", ".join(f"r[{order[i]}]" for i in range(len(layout.paths)))
    source = (
        f"def values_{layout.message_type.__name__}(data):\n"
        "    if _len(data) != _size:\n"
        "        return None\n"
        "    r = _unpack(data)\n"
        f"    if {' or '.join(checks) or 'False'}:\n"
        "        return None\n"
        f"    return ({picked},)\n"
    )
    exec(compile(source, f"<flat values of {layout!r}>", "exec"), names)
    read: Callable[[bytes], tuple[Any, ...] | None] = names[
        f"values_{layout.message_type.__name__}"
    ]  # type: ignore[assignment]
    return read
