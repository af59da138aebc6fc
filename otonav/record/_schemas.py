"""ROS 2 layouts and ``ros2msg`` definitions of the otonav message types.

A *layout* is the ROS field list of a message class: each field's name (our pydantic
field names are the ROS names) and its ROS type, in the model's field order (the wire
order). A layout is generated from the pydantic fields (``float`` -> ``float64``, ``int``
-> ``int64``, ``str`` -> ``string``, a message -> its type, ``tuple[X, ...]`` -> ``X[]``);
what the models cannot say -- ``float32`` vs ``float64``, ``uint32`` vs ``int64``, fixed
array sizes such as ``float64[36]`` -- is the short table of ROS types below, checked
against the model. Both the schema text (this module) and the CDR codec
(:mod:`otonav.record.cdr`) are driven by the same layouts; the SIL layer compares the
schemas with the ``.msg`` files of real ROS 2 distributions.

The definition text is what ``ros2 bag record`` stores in an MCAP schema record
(encoding ``ros2msg``, rosbag2's ``LocalMessageDefinitionSource``): the top-level
``.msg`` text, then every dependency, depth first in sorted name order, each once,
preceded by ``"\\n"``, a line of 80 ``=`` and a line ``MSG: pkg/Type``.
"""

from __future__ import annotations

import functools
import re
import typing
from dataclasses import dataclass
from typing import Final

from otonav.msgs import (
    DiagnosticStatus,
    Frame,
    HardwareStatus,
    Imu,
    LaserScan,
    Log,
    MapMetaData,
    Message,
    OccupancyGrid,
    ParameterValue,
    PoseWithCovariance,
    Time,
    TwistWithCovariance,
)

__all__ = (
    "PRIMITIVES",
    "SEQUENCE",
    "Constant",
    "Field",
    "Layout",
    "layout_for",
    "schema_for",
    "short_name",
)

SEQUENCE: Final = -1
"""``Field.array`` of an unbounded sequence (``T[]``)."""

PRIMITIVES: Final[dict[str, type]] = {
    "bool": bool,
    "byte": int,
    "char": int,
    "int8": int,
    "uint8": int,
    "int16": int,
    "uint16": int,
    "int32": int,
    "uint32": int,
    "int64": int,
    "uint64": int,
    "float32": float,
    "float64": float,
    "string": str,
}
"""ROS 2 primitive type -> the Python type our models hold it in."""

_ROS_TYPE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*/msg/[A-Z][A-Za-z0-9]*$")
_FIELD_NAME = re.compile(r"^[a-z][a-z0-9_]*$")
_DELIMITER: Final = "=" * 80 + "\n"


@dataclass(frozen=True, slots=True)
class Field:
    """One ROS field: ``type`` is a primitive name or a message class; ``array`` is
    ``None`` (a single value), :data:`SEQUENCE` (``T[]``) or n > 0 (``T[n]``)."""

    name: str
    type: str | type[Message]
    array: int | None = None

    @property
    def msg_type(self) -> str:
        """The type as written in a ``.msg`` file: ``float64[36]``, ``std_msgs/Header``."""
        base = self.type if isinstance(self.type, str) else short_name(self.type)
        if self.array is None:
            return base
        return f"{base}[]" if self.array == SEQUENCE else f"{base}[{self.array}]"


@dataclass(frozen=True, slots=True)
class Constant:
    """A ``.msg`` constant such as ``byte DEBUG=10``."""

    type: str
    name: str
    value: int


@dataclass(frozen=True, slots=True)
class Layout:
    """The ROS layout of a message class, fields in wire order."""

    message: type[Message]
    fields: tuple[Field, ...]
    constants: tuple[Constant, ...] = ()


def short_name(message: type[Message]) -> str:
    """``pkg/msg/Type`` -> ``pkg/Type``, the form used inside ``.msg`` text."""
    pkg, _, name = message.ros_type.split("/")
    return f"{pkg}/{name}"


_ROS_TYPES: Final[dict[type, str]] = {
    Time: "int32 sec, uint32 nanosec",
    Log: "uint8 level, uint32 line",
    PoseWithCovariance: "float64[36] covariance",
    TwistWithCovariance: "float64[36] covariance",
    ParameterValue: "uint8 type, byte[] byte_array_value",
    Imu: "float64[9] orientation_covariance, float64[9] angular_velocity_covariance, "
    "float64[9] linear_acceleration_covariance",
    LaserScan: "float32 angle_min, float32 angle_max, float32 angle_increment, "
    "float32 time_increment, float32 scan_time, float32 range_min, float32 range_max, "
    "float32[] ranges, float32[] intensities",
    MapMetaData: "float32 resolution, uint32 width, uint32 height",
    OccupancyGrid: "int8[] data",
    Frame: "uint32 id, uint8 dlc, uint8[8] data",
    DiagnosticStatus: "byte level",
    HardwareStatus: "uint8 level",
}
"""The fields whose ROS 2 (Humble/Jazzy) type is not the one generated from the model."""

_CONSTANTS: Final[dict[type, str]] = {
    Log: "DEBUG INFO WARN ERROR FATAL",
    DiagnosticStatus: "OK WARN ERROR STALE",
}
"""The ``byte`` constants of a ``.msg``, valued as the model's class attributes."""

_ROS_FIELD = re.compile(r"(\w+)(?:\[(\d*)\])? (\w+)")
_GENERATED_PRIMITIVE: Final[dict[type, str]] = {
    str: "string",
    float: "float64",
    int: "int64",
    bool: "bool",
}


def _is_message(tp: object) -> typing.TypeGuard[type[Message]]:
    return isinstance(tp, type) and issubclass(tp, Message)


def _field_from_annotation(message: type[Message], name: str, tp: object) -> Field:
    """A generated field: str/float/int/bool -> string/float64/int64/bool, a message ->
    its type, ``tuple[X, ...]`` -> ``X[]``."""
    if _is_message(tp):
        return Field(name, tp)
    if isinstance(tp, type) and tp in _GENERATED_PRIMITIVE:
        return Field(name, _GENERATED_PRIMITIVE[tp])
    args = typing.get_args(tp)
    if typing.get_origin(tp) is tuple and len(args) == 2 and args[1] is Ellipsis:
        item = _field_from_annotation(message, name, args[0])
        if item.array is None:
            return Field(name, item.type, SEQUENCE)
    raise TypeError(f"{message.__name__}.{name}: no ROS 2 type for {tp!r}")


def _from_table(text: str) -> dict[str, Field | None]:
    """``"float32 a, uint8[8] b"`` -> the fields ``a`` and ``b`` by name."""
    fields: dict[str, Field | None] = {}
    for match in map(_ROS_FIELD.fullmatch, filter(None, text.split(", "))):
        assert match is not None, text
        kind, size, name = match.groups()
        array = None if size is None else int(size) if size else SEQUENCE
        fields[name] = Field(name, kind, array)
    return fields


def _python_type(field: Field) -> object:
    """The annotation our model must carry for ``field``."""
    base: object = PRIMITIVES[field.type] if isinstance(field.type, str) else field.type
    if field.array is None:
        return base
    return tuple[base, ...]  # type: ignore[valid-type]


def _check(layout: Layout) -> None:
    """Refuse a layout that does not match its pydantic model or is not valid ROS."""
    message = layout.message
    where = message.__name__
    if not _ROS_TYPE.match(getattr(message, "ros_type", "")):
        raise ValueError(f"{where}: ros_type must look like 'pkg/msg/Type'")
    model_fields = message.model_fields
    for field in layout.fields:
        if not _FIELD_NAME.match(field.name):
            raise ValueError(f"{where}.{field.name}: not a valid ROS field name")
        annotation = model_fields[field.name].annotation
        if annotation != _python_type(field):
            raise ValueError(
                f"{where}.{field.name}: model type {annotation!r} does not hold {field.msg_type}"
            )


@functools.cache
def layout_for(message: type[Message]) -> Layout:
    """The checked ROS layout of ``message``: generated, with the table's ROS types."""
    # A subclass (a lazily decoded replay input) has its base's ROS types.
    home = next((c for c in message.__mro__ if c in _ROS_TYPES or c in _CONSTANTS), message)
    table = _from_table(_ROS_TYPES.get(home, ""))
    fields = tuple(
        table.pop(name, None) or _field_from_annotation(message, name, info.annotation)
        for name, info in message.model_fields.items()
    )
    if table:
        raise ValueError(f"{message.__name__}: no model field for {sorted(table)}")
    names = _CONSTANTS.get(home, "").split()
    constants = tuple(Constant("byte", name, getattr(message, name)) for name in names)
    layout = Layout(message, fields, constants)
    _check(layout)
    return layout


def _msg_text(layout: Layout) -> str:
    """The ``.msg`` text of one type: constants, then ``type name`` per field."""
    lines = [f"{c.type} {c.name}={c.value}" for c in layout.constants]
    lines += [f"{f.msg_type} {f.name}" for f in layout.fields]
    return "".join(line + "\n" for line in lines)


def _dependencies(layout: Layout) -> list[type[Message]]:
    """The message types ``layout``'s fields use, sorted by name, each once."""
    deps = {short_name(f.type): f.type for f in layout.fields if not isinstance(f.type, str)}
    return [deps[name] for name in sorted(deps)]


@functools.cache
def schema_for(message: type[Message]) -> tuple[str, str]:
    """``(schema name, ros2msg definition)`` for an MCAP schema record of ``message``.

    The name is the ROS type (``sensor_msgs/msg/LaserScan``); the definition follows
    rosbag2: top-level text, then each dependency (depth first) behind a delimiter.
    """
    seen: set[type[Message]] = set()

    def full_text(current: type[Message]) -> str:
        text = _msg_text(layout_for(current))
        for dep in _dependencies(layout_for(current)):
            if dep not in seen:
                seen.add(dep)
                text += f"\n{_DELIMITER}MSG: {short_name(dep)}\n{full_text(dep)}"
        return text

    return message.ros_type, full_text(message)
