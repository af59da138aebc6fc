"""The base of every message: a frozen pydantic model that knows its ROS 2 type name."""

from __future__ import annotations

from typing import Any, ClassVar, Self

from pydantic import BaseModel, ConfigDict

_new = object.__new__
# BaseModel's slots, set through their descriptors: ``object.__setattr__`` looks each
# one up on the type first (fast() took 2.0 us -> 1.0 us for a Vector3, measured).
_set_dict = BaseModel.__dict__["__dict__"].__set__
_set_fields_set = BaseModel.__dict__["__pydantic_fields_set__"].__set__
_set_extra = BaseModel.__dict__["__pydantic_extra__"].__set__
_set_private = BaseModel.__dict__["__pydantic_private__"].__set__


class Message(BaseModel):
    """A frozen, validated message. ``ros_type`` is the ROS 2 type it stands for
    (``pkg/msg/Name``); recordings use it as the schema name.

    Messages built inside the stack from already-typed values use ``model_construct``
    (no validation) on the hot path; data entering from outside is validated.
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
        no defaults. The stack's hot path (a 30 s run builds ~70k messages): 0.33 s of
        a 2.07 s profiled run went to ``model_construct``, which fills defaults and
        fields_set for each call; this is the same object, built by hand.
        """
        message = _new(cls)
        _set_dict(message, values)
        _set_fields_set(message, cls._otonav_fields)
        _set_extra(message, None)
        _set_private(message, None)
        return message
