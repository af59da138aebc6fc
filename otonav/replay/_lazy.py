"""Recorded messages decoded on first use.

A replay feeds every recorded input to the actors, but an actor reads only some of them:
the navigator queues each /odom (100 Hz) and looks at a few per step (20 Hz), 737 of the
acceptance recording's 1342. Decoding them all was a quarter of a navigator replay
(25 ms of 113); an Odometry decodes in 6-13 us, a :func:`lazy` one is made in 0.5 us.

A lazy message is an instance of a subclass of its message class that holds only its CDR
bytes. Its first attribute access of any kind (a field, a method, ``__dict__``, which
every pydantic method goes through, and the comparison and hash operators) decodes it
with :func:`~otonav.record.cdr.decode`, takes the decoded fields and switches the
object's class to the message class itself. From then on it is that message, field for
field, type for type: ``type(m) is Odometry``, equal to and hashing like the eagerly
decoded one (tests check each operation). Before its first use only ``type(m)`` tells
it apart, and a publisher's strict type check compares ``type(m)``: the feeder delivers
to the mailboxes itself, and when an actor relays an input it never looked at, the
publisher's slow path asks the object for its ``__class__``, which decodes it.

Two shortcuts: a stamped message's ``header`` (its first field on the wire) is decoded
alone, and the message stays lazy until anything else is read; and :func:`input_maker`
feeds the bridge's fixed-layout streams as the flat messages it published
(:mod:`otonav.msgs._flat`) when the bytes are exactly that layout's.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from otonav.msgs import Header, Message
from otonav.msgs._flat import FlatLayout
from otonav.msgs._stand_in import become, stand_in_class
from otonav.msgs._stand_in import get as _get
from otonav.record._schemas import layout_for
from otonav.record.cdr import decode, flat_values

__all__ = ("input_maker", "is_lazy", "lazy", "lazy_maker", "materialize")

_new = object.__new__

M = TypeVar("M", bound=Message)

_KEY = "\0cdr"
"""Where a lazy message keeps its bytes in its ``__dict__``: no field can have this name,
so every field lookup misses and reaches ``__getattribute__``."""

_LAZY: dict[type[Message], type[Message]] = {}
_REAL: dict[type[Message], type[Message]] = {}


def materialize(message: M) -> M:
    """Decode a lazy ``message`` in place (no-op for a decoded one); returns it."""
    real = _REAL.get(type(message))
    if real is None:
        return message
    fields = _get(message, "__dict__")
    data = fields.get(_KEY)
    # No bytes: a copy taken from an already decoded message (pydantic's __copy__ builds
    # the copy with type(self), read before the original decoded itself).
    # A header read before (see _lazy_class) is the message's own: not decoded again.
    decoded = None if data is None else decode(real, data, fields.get("header"))
    become(message, real, None if decoded is None else _get(decoded, "__dict__"))
    return message


def _lazy_class(real: type[Message]) -> type[Message]:
    layout = layout_for(real)
    stamped = bool(layout.fields) and layout.fields[0].name == "header"
    stamped = stamped and layout.fields[0].type is Header

    def __getattribute__(self: Message, name: str) -> Any:
        if name == "header" and stamped:
            # A stamped message's header comes first on the wire, where a Header alone
            # would be: decode just it, and keep the message lazy. The navigator reads
            # the stamps of ~4 queued /odom per scan to find the pose at the scan's
            # stamp, and the rest of only one (Odometry 5.0 us, its Header 1.2 us).
            fields = _get(self, "__dict__")
            data = fields.get(_KEY)
            if data is not None:
                header = fields.get("header")
                if header is None:
                    try:
                        header = fields["header"] = decode(Header, data)
                    except ValueError:  # damaged: the whole message's decode says so
                        header = None
                if header is not None:
                    return header
        materialize(self)
        return _get(self, name)

    cls = stand_in_class(
        real,
        f"Lazy{real.__name__}",
        module=__name__,
        doc=f"A {real.__name__} still in CDR: decoded on first use.",
        getattribute=__getattribute__,
        materialize=materialize,
    )
    _LAZY[real] = cls
    _REAL[cls] = real
    return cls


def lazy(message_type: type[M], data: bytes) -> M:
    """A ``message_type`` message that decodes ``data`` (CDR with its encapsulation
    header) the first time it is used. Bad data raises ``ValueError`` then."""
    return lazy_maker(message_type)(data)


def lazy_maker(message_type: type[M]) -> Callable[[bytes], M]:
    """``lambda data: lazy(message_type, data)``, with the class looked up once (the
    replay's feeder makes one per recorded input)."""
    cls = _LAZY.get(message_type) or _lazy_class(message_type)

    def make_lazy(data: bytes) -> M:
        message: M = _new(cls)  # type: ignore[assignment]
        _get(message, "__dict__")[_KEY] = data  # its state: when decoded (as a flat one's)
        return message

    return make_lazy


def input_maker(
    message_type: type[M], layouts: Sequence[FlatLayout[Any]] = ()
) -> Callable[[bytes], M]:
    """How a replay makes its ``message_type`` inputs from their CDR bytes: as a fixed
    layout's flat message (:mod:`otonav.msgs._flat`) when ``layouts`` has one for the
    type and the bytes are that layout's template with its values in place (what the
    bridge publishes: the same kind of object the live stack handed the actors, whose
    readers take the values without building anything), else lazily. Either is, from
    its first use, the decoded message (tested on every recorded /odom, /tf, /imu and
    /clock of the acceptance run)."""
    make_lazy = lazy_maker(message_type)
    layout = next((f for f in layouts if f.message_type is message_type), None)
    if layout is None:
        return make_lazy
    values_of = flat_values(layout)

    def make(data: bytes) -> M:
        values = values_of(data)
        if values is None:
            return make_lazy(data)
        message: M = layout(*values)
        return message

    return make


def is_lazy(message: object) -> bool:
    """Whether ``message`` is a lazy message not decoded yet."""
    return type(message) in _REAL
