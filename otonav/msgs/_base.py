"""The base of every message: a frozen pydantic model that knows its ROS 2 type name."""

from __future__ import annotations

from typing import Any, ClassVar, Self, TypeVar

from pydantic import BaseModel, ConfigDict

M = TypeVar("M", bound="Message")

_new = object.__new__
_setstate = BaseModel.__setstate__


def set_state(message: Message, fields: dict[str, Any], fields_set: set[str]) -> None:
    """Give ``message`` (made with ``object.__new__``) its pydantic state: ``fields`` as
    they are (trusted, already typed), no constructor run. Through the pickle protocol
    (``__setstate__``, how pickle and ``copy`` rebuild a model), the fastest of
    pydantic's public ways: a Vector3 in 1.7 us against 4.4 with ``model_construct`` and
    2.1 validated (ADR 0086, ``benchmarks/message_bench.py``)."""
    _setstate(
        message,
        {
            "__dict__": fields,
            "__pydantic_fields_set__": fields_set,
            "__pydantic_extra__": None,
            "__pydantic_private__": None,
        },
    )


def make(cls: type[M], fields: dict[str, Any], fields_set: set[str]) -> M:
    """A ``cls`` message holding ``fields`` (:func:`set_state`)."""
    message: M = _new(cls)
    set_state(message, fields, fields_set)
    return message


class Message(BaseModel):
    """A frozen, validated message. ``ros_type`` is the ROS 2 type it stands for
    (``pkg/msg/Name``); recordings use it as the schema name.

    Messages built inside the stack from already-typed values use :meth:`fast` (no
    validation) on the hot path; data entering from outside is validated.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")
    ros_type: ClassVar[str]
    _otonav_fields: ClassVar[set[str]] = set()

    @classmethod
    def __pydantic_init_subclass__(cls, **kwargs: Any) -> None:
        super().__pydantic_init_subclass__(**kwargs)
        cls._otonav_fields = set(cls.model_fields)

    @classmethod
    def fast(cls, **values: Any) -> Self:
        """Build from trusted, already-typed values, giving EVERY field: no validation,
        no defaults. The stack's hot path (~280 messages per sim second):
        ``model_construct`` walks every field's aliases and defaults for each call, 2.6x
        the cost; this is the same object (:func:`make`).
        """
        message = _new(cls)
        _setstate(  # make(), inlined: a call less on the hot path
            message,
            {
                "__dict__": values,
                "__pydantic_fields_set__": cls._otonav_fields,
                "__pydantic_extra__": None,
                "__pydantic_private__": None,
            },
        )
        return message
