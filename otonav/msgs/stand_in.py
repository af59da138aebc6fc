"""Stand-in messages: what :mod:`otonav.msgs.flat` and :mod:`otonav.replay.lazy` share.

A stand-in is an instance of a subclass of a message class that holds only what it needs
to become the message (a fixed layout's values, or CDR bytes) under a key no field can
have. On first use it builds the message's fields in place and switches its class to the
message class: from then on it *is* that message. This module has the pieces both kinds
use: the stand-in class itself, the slot setters that make a message without pydantic's
constructor, the switch, and the operators that build the message before comparing,
hashing or printing it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from pydantic import BaseModel

from otonav.msgs._base import Message

get = object.__getattribute__
new = object.__new__
set_class = object.__setattr__
# BaseModel's slots, set through their descriptors (see Message.fast).
set_dict = BaseModel.__dict__["__dict__"].__set__
set_fields_set = BaseModel.__dict__["__pydantic_fields_set__"].__set__
set_extra = BaseModel.__dict__["__pydantic_extra__"].__set__
set_private = BaseModel.__dict__["__pydantic_private__"].__set__


def make(cls: type[Message], fields: dict[str, Any], fields_set: set[str]) -> Message:
    """A message of ``cls`` (a message class or a stand-in class) with these ``__dict__``
    entries, built as :meth:`Message.fast` does."""
    message: Message = new(cls)
    set_dict(message, fields)
    set_fields_set(message, fields_set)
    set_extra(message, None)
    set_private(message, None)
    return message


def become(message: Message, real: type[Message], fields: dict[str, Any] | None) -> None:
    """Make the stand-in ``message`` the ``real`` message with ``fields`` (``None``: it
    has its fields already, e.g. a copy of one that was built)."""
    if fields is not None:
        set_dict(message, fields)
    set_class(message, "__class__", real)


def operators(materialize: Callable[[Any], Message]) -> dict[str, Any]:
    """``==``, ``hash``, ``repr`` and ``str`` of a stand-in class: each builds the
    message first (``materialize(self)``) and answers as the message does."""

    def __eq__(self: Message, other: object) -> bool:
        return materialize(self) == other

    def __hash__(self: Message) -> int:
        return hash(materialize(self))

    def __repr__(self: Message) -> str:
        return repr(materialize(self))

    def __str__(self: Message) -> str:
        return str(materialize(self))

    return {"__eq__": __eq__, "__hash__": __hash__, "__repr__": __repr__, "__str__": __str__}


def stand_in_class(
    real: type[Message],
    name: str,
    *,
    module: str,
    doc: str,
    getattribute: Callable[[Message, str], Any],
    materialize: Callable[[Any], Message],
    **attributes: Any,
) -> type[Message]:
    """A subclass ``name`` of ``real`` whose every attribute access goes through
    ``getattribute`` and whose operators build the message first (:func:`operators`),
    plus ``attributes``.

    Its layout is the base's exactly (``__slots__ = ()``), so an instance can switch its
    ``__class__`` to ``real``. It is made by ``type.__new__`` under pydantic's
    metaclass, not the metaclass's own ``__new__``: a model class like its base
    (``type(cls)`` is the same), without pydantic collecting its fields and building its
    validator again (~0.5 ms per message type; the class only stands in until first use).
    """
    namespace = {
        "__getattribute__": getattribute,
        **operators(materialize),
        "__module__": module,
        "__qualname__": name,
        "__doc__": doc,
        "__slots__": (),
        **attributes,
    }
    metaclass: Any = type(real)
    cls: type[Message] = type.__new__(metaclass, name, (real,), namespace)
    return cls
