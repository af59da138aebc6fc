"""ROS 2 layouts and ``ros2msg`` definitions of the otonav message types.

A *layout* is the ROS field list of a message class: each field's name (our pydantic
field names are the ROS names) and its ROS type. The pydantic models do not say
everything ROS needs -- ``float32`` vs ``float64``, ``uint32`` vs ``int64``, fixed
array sizes such as ``float64[36]`` -- so the known ROS layouts are an explicit table
below. A message class that is not in the table (a type with no ROS equivalent) gets a
layout generated from its pydantic fields. Both the schema text (this module) and the
CDR encoder (:mod:`otonav.record.cdr`) are driven by the same layouts, and every layout
is checked against its pydantic model, so the two cannot drift apart silently.

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
    Clock,
    DiagnosticArray,
    DiagnosticStatus,
    Frame,
    HardwareStatus,
    Header,
    Imu,
    KeyValue,
    LaserScan,
    Log,
    MapMetaData,
    Message,
    NavDiagnostics,
    NavState,
    OccupancyGrid,
    Odometry,
    Parameter,
    ParameterEvent,
    ParameterValue,
    Point,
    Pose,
    PoseStamped,
    PoseWithCovariance,
    Quaternion,
    SafetyState,
    TFMessage,
    Time,
    Transform,
    TransformStamped,
    Twist,
    TwistStamped,
    TwistWithCovariance,
    Vector3,
    WheelCommand,
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


_F = Field
_HEADER = _F("header", Header)
_XYZ = (_F("x", "float64"), _F("y", "float64"), _F("z", "float64"))

_KNOWN: Final[dict[type[Message], tuple[tuple[Field, ...], tuple[Constant, ...]]]] = {
    Time: ((_F("sec", "int32"), _F("nanosec", "uint32")), ()),
    Header: ((_F("stamp", Time), _F("frame_id", "string")), ()),
    Clock: ((_F("clock", Time),), ()),
    Log: (
        (
            _F("stamp", Time),
            _F("level", "uint8"),
            _F("name", "string"),
            _F("msg", "string"),
            _F("file", "string"),
            _F("function", "string"),
            _F("line", "uint32"),
        ),
        tuple(
            Constant("byte", name, value)
            for name, value in (
                ("DEBUG", 10),
                ("INFO", 20),
                ("WARN", 30),
                ("ERROR", 40),
                ("FATAL", 50),
            )
        ),
    ),
    Vector3: (_XYZ, ()),
    Point: (_XYZ, ()),
    Quaternion: ((*_XYZ, _F("w", "float64")), ()),
    Pose: ((_F("position", Point), _F("orientation", Quaternion)), ()),
    PoseStamped: ((_HEADER, _F("pose", Pose)), ()),
    PoseWithCovariance: ((_F("pose", Pose), _F("covariance", "float64", 36)), ()),
    Twist: ((_F("linear", Vector3), _F("angular", Vector3)), ()),
    ParameterValue: (
        (
            _F("type", "uint8"),
            _F("bool_value", "bool"),
            _F("integer_value", "int64"),
            _F("double_value", "float64"),
            _F("string_value", "string"),
            _F("byte_array_value", "byte", SEQUENCE),
            _F("bool_array_value", "bool", SEQUENCE),
            _F("integer_array_value", "int64", SEQUENCE),
            _F("double_array_value", "float64", SEQUENCE),
            _F("string_array_value", "string", SEQUENCE),
        ),
        (),
    ),
    Parameter: ((_F("name", "string"), _F("value", ParameterValue)), ()),
    ParameterEvent: (
        (
            _F("stamp", Time),
            _F("node", "string"),
            _F("new_parameters", Parameter, SEQUENCE),
            _F("changed_parameters", Parameter, SEQUENCE),
            _F("deleted_parameters", Parameter, SEQUENCE),
        ),
        (),
    ),
    TwistStamped: ((_HEADER, _F("twist", Twist)), ()),
    TwistWithCovariance: ((_F("twist", Twist), _F("covariance", "float64", 36)), ()),
    Transform: ((_F("translation", Vector3), _F("rotation", Quaternion)), ()),
    TransformStamped: (
        (_HEADER, _F("child_frame_id", "string"), _F("transform", Transform)),
        (),
    ),
    Odometry: (
        (
            _HEADER,
            _F("child_frame_id", "string"),
            _F("pose", PoseWithCovariance),
            _F("twist", TwistWithCovariance),
        ),
        (),
    ),
    Imu: (
        (
            _HEADER,
            _F("orientation", Quaternion),
            _F("orientation_covariance", "float64", 9),
            _F("angular_velocity", Vector3),
            _F("angular_velocity_covariance", "float64", 9),
            _F("linear_acceleration", Vector3),
            _F("linear_acceleration_covariance", "float64", 9),
        ),
        (),
    ),
    LaserScan: (
        (
            _HEADER,
            _F("angle_min", "float32"),
            _F("angle_max", "float32"),
            _F("angle_increment", "float32"),
            _F("time_increment", "float32"),
            _F("scan_time", "float32"),
            _F("range_min", "float32"),
            _F("range_max", "float32"),
            _F("ranges", "float32", SEQUENCE),
            _F("intensities", "float32", SEQUENCE),
        ),
        (),
    ),
    TFMessage: ((_F("transforms", TransformStamped, SEQUENCE),), ()),
    MapMetaData: (
        (
            _F("map_load_time", Time),
            _F("resolution", "float32"),
            _F("width", "uint32"),
            _F("height", "uint32"),
            _F("origin", Pose),
        ),
        (),
    ),
    OccupancyGrid: (
        (_HEADER, _F("info", MapMetaData), _F("data", "int8", SEQUENCE)),
        (),
    ),
    WheelCommand: ((_HEADER, _F("left", "float64"), _F("right", "float64")), ()),
    NavState: (
        (
            _HEADER,
            _F("state", "string"),
            _F("distance_to_goal", "float64"),
            _F("heading_error", "float64"),
            _F("closest_ahead", "float64"),
        ),
        (),
    ),
    NavDiagnostics: (
        (
            _HEADER,
            _F("planner", "string"),
            _F("state", "string"),
            _F("reason", "string"),
            _F("stage", "string"),
            _F("v", "float64"),
            _F("omega", "float64"),
            _F("admissible", "int64"),
            _F("samples", "int64"),
            _F("best_score", "float64"),
            _F("clearance", "float64"),
            _F("path_length", "float64"),
            _F("replans", "int64"),
        ),
        (),
    ),
    SafetyState: (
        (
            _HEADER,
            _F("reason", "string"),
            _F("scale", "float64"),
            _F("nearest", "float64"),
            _F("v_in", "float64"),
            _F("omega_in", "float64"),
            _F("v_out", "float64"),
            _F("omega_out", "float64"),
        ),
        (),
    ),
    Frame: (
        (
            _HEADER,
            _F("id", "uint32"),
            _F("is_rtr", "bool"),
            _F("is_extended", "bool"),
            _F("is_error", "bool"),
            _F("dlc", "uint8"),
            _F("data", "uint8", 8),
        ),
        (),
    ),
    KeyValue: ((_F("key", "string"), _F("value", "string")), ()),
    DiagnosticStatus: (
        (
            _F("level", "byte"),
            _F("name", "string"),
            _F("message", "string"),
            _F("hardware_id", "string"),
            _F("values", KeyValue, SEQUENCE),
        ),
        tuple(
            Constant("byte", name, value)
            for name, value in (("OK", 0), ("WARN", 1), ("ERROR", 2), ("STALE", 3))
        ),
    ),
    DiagnosticArray: ((_HEADER, _F("status", DiagnosticStatus, SEQUENCE)), ()),
    HardwareStatus: (
        (
            _HEADER,
            _F("level", "uint8"),
            _F("ready", "bool"),
            _F("fault", "string"),
            _F("message", "string"),
        ),
        (),
    ),
}
"""The ROS 2 layouts (Humble/Jazzy) of the message types we share with ROS."""

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


def _generate(message: type[Message]) -> Layout:
    fields = tuple(
        _field_from_annotation(message, name, info.annotation)
        for name, info in message.model_fields.items()
    )
    return Layout(message, fields)


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
    names = [f.name for f in layout.fields]
    if sorted(names) != sorted(model_fields):
        raise ValueError(f"{where}: layout fields {names} != model fields {list(model_fields)}")
    for field in layout.fields:
        if not _FIELD_NAME.match(field.name):
            raise ValueError(f"{where}.{field.name}: not a valid ROS field name")
        if isinstance(field.type, str) and field.type not in PRIMITIVES:
            raise ValueError(f"{where}.{field.name}: unknown primitive {field.type!r}")
        if field.array is not None and field.array != SEQUENCE and field.array < 1:
            raise ValueError(f"{where}.{field.name}: bad array size {field.array}")
        annotation = model_fields[field.name].annotation
        if annotation != _python_type(field):
            raise ValueError(
                f"{where}.{field.name}: model type {annotation!r} does not hold {field.msg_type}"
            )
    for constant in layout.constants:
        if getattr(message, constant.name, None) != constant.value:
            raise ValueError(f"{where}.{constant.name}: differs from the model's constant")


@functools.cache
def layout_for(message: type[Message]) -> Layout:
    """The checked ROS layout of ``message``: from the table, else generated."""
    known = _KNOWN.get(message)
    if known is None:
        # A subclass that adds no field (a lazily decoded replay input) is its base.
        base = next((c for c in message.__mro__[1:] if c in _KNOWN), None)
        if base is not None and base.model_fields.keys() == message.model_fields.keys():
            known = _KNOWN[base]
    layout = _generate(message) if known is None else Layout(message, *known)
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
