"""Stand-in messages: what :mod:`otonav.msgs._flat` and :mod:`otonav.replay._lazy` share.

A stand-in is an instance of a subclass of a message class that holds only what it needs
to become the message (a fixed layout's values, or CDR bytes) under a key no field can
have. On first use it builds the message's fields in place and switches its class to the
message class: from then on it *is* that message. This module has the pieces both kinds
use: the stand-in class itself, the switch, and the operators that build the message
before comparing, hashing or printing it. A stand-in gets its pydantic state as every
message built without validation does (:func:`~otonav.msgs._base.make`: pydantic's
``__setstate__``); nothing here touches BaseModel's slots (ADR 0086).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from otonav.msgs._base import Message, make, set_state

__all__ = ("become", "get", "make", "operators", "stand_in_class")

get = object.__getattribute__
"""A stand-in's own attributes (its ``__dict__``), past its ``__getattribute__``."""
_set_class = object.__setattr__


def become(
    message: Message,
    real: type[Message],
    fields: dict[str, Any] | None,
    fields_set: set[str] | None = None,
) -> None:
    """Make the stand-in ``message`` the ``real`` message holding ``fields`` (``None``:
    it has its state already, e.g. a copy of one that was built), then switch its class
    (the same layout: a stand-in class has ``__slots__ = ()``)."""
    if fields is not None:
        set_state(message, fields, real._otonav_fields if fields_set is None else fields_set)
    _set_class(message, "__class__", real)


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
