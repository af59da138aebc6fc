"""The ROS 2 type description hash (``RIHS01_<sha256>``, REP 2011) of a message type.

rosbag2 (Iron and later) stores it per topic: ``type_description_hash`` in
``metadata.yaml`` and ``topic_type_hash`` in an MCAP channel's metadata; a ROS 2 node
uses it to tell two definitions of one type name apart. It is the SHA-256 of a JSON
text: the type's description (its name and fields, each field's type as rosidl's
``FieldType`` id, array capacity, string bound and nested type name) and those of every
type it refers to, sorted by name. Constants and default values are not part of it;
an empty message gets rosidl's placeholder field. Computed from the same layouts that
drive the schema text and the CDR encoder (:mod:`otonav.record._schemas`); the gate
checks it against rosbags' implementation and the hashes of the stock ROS types.
"""

from __future__ import annotations

import functools
import hashlib
import json
from typing import Any, Final

from otonav.msgs import Message
from otonav.record._schemas import SEQUENCE, Field, layout_for

__all__ = ("rihs01",)

_TYPE_ID: Final[dict[str, int]] = {
    "int8": 2,
    "uint8": 3,
    "char": 3,  # a .msg ``char`` is uint8 in ROS 2's IDL
    "int16": 4,
    "uint16": 5,
    "int32": 6,
    "uint32": 7,
    "int64": 8,
    "uint64": 9,
    "float32": 10,
    "float64": 11,
    "bool": 15,
    "byte": 16,
    "string": 17,
}
_NESTED: Final = 1
_ARRAY, _BOUNDED, _UNBOUNDED = 48, 96, 144  # offsets of T[n], T[<=n] and T[]
_PLACEHOLDER: Final = Field("structure_needs_at_least_one_member", "uint8")


def _field(field: Field, refs: dict[str, dict[str, Any]]) -> dict[str, Any]:
    offset = 0 if field.array is None else _UNBOUNDED if field.array == SEQUENCE else _ARRAY
    capacity = field.array if field.array not in (None, SEQUENCE) else 0
    nested = ""
    if isinstance(field.type, str):
        type_id = _TYPE_ID[field.type] + offset
    else:
        type_id = _NESTED + offset
        nested = field.type.ros_type
        _describe(field.type, refs)
    return {
        "name": field.name,
        "type": {
            "type_id": type_id,
            "capacity": capacity,
            "string_capacity": 0,
            "nested_type_name": nested,
        },
    }


def _describe(message: type[Message], refs: dict[str, dict[str, Any]]) -> dict[str, Any]:
    name = message.ros_type
    if name not in refs:
        refs[name] = {}  # reserved before the fields: a type is described once
        fields = layout_for(message).fields or (_PLACEHOLDER,)
        refs[name].update(type_name=name, fields=[_field(f, refs) for f in fields])
    return refs[name]


@functools.cache
def rihs01(message: type[Message]) -> str:
    """``RIHS01_`` and the hex SHA-256 of ``message``'s type description."""
    refs: dict[str, dict[str, Any]] = {}
    top = _describe(message, refs)
    description = {
        "type_description": top,
        "referenced_type_descriptions": [
            refs[name] for name in sorted(refs) if name != message.ros_type
        ],
    }
    # json.dumps' default separators (", ", ": ") are rosidl's.
    return "RIHS01_" + hashlib.sha256(json.dumps(description).encode()).hexdigest()
