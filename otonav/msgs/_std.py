"""builtin_interfaces, std_msgs, rosgraph_msgs and rcl_interfaces shapes."""

from __future__ import annotations

from typing import ClassVar

from otonav.msgs._base import Message


def split_seconds(seconds: float) -> tuple[int, int]:
    """``seconds`` as a Time's ``(sec, nanosec)``, rounded to the nanosecond (what
    :meth:`Time.from_seconds` holds, for a fixed-layout message's stamp)."""
    sec, nanosec = divmod(round(seconds * 1e9), 1_000_000_000)
    return sec, nanosec


class Time(Message):
    """builtin_interfaces/msg/Time: sim time as whole seconds + nanoseconds."""

    ros_type: ClassVar[str] = "builtin_interfaces/msg/Time"
    sec: int = 0
    """Whole seconds."""
    nanosec: int = 0
    """Nanoseconds, 0 <= nanosec < 1e9."""

    @classmethod
    def from_seconds(cls, seconds: float) -> Time:
        sec, nanosec = split_seconds(seconds)
        return cls.fast(sec=sec, nanosec=nanosec)

    def to_seconds(self) -> float:
        return self.sec + self.nanosec * 1e-9

    def to_nanoseconds(self) -> int:
        return self.sec * 1_000_000_000 + self.nanosec


class Header(Message):
    """std_msgs/msg/Header."""

    ros_type: ClassVar[str] = "std_msgs/msg/Header"
    stamp: Time = Time()
    """Sim time the data refers to."""
    frame_id: str = ""
    """Coordinate frame of the data."""


class Clock(Message):
    """rosgraph_msgs/msg/Clock: the sim time on ``/clock``."""

    ros_type: ClassVar[str] = "rosgraph_msgs/msg/Clock"
    clock: Time = Time()


class Log(Message):
    """rcl_interfaces/msg/Log: a ``/rosout`` line (actor lifecycle, crashes, warnings)."""

    ros_type: ClassVar[str] = "rcl_interfaces/msg/Log"
    DEBUG: ClassVar[int] = 10
    INFO: ClassVar[int] = 20
    WARN: ClassVar[int] = 30
    ERROR: ClassVar[int] = 40
    FATAL: ClassVar[int] = 50
    stamp: Time = Time()
    level: int = 20
    name: str = ""
    """The actor (logger) name."""
    msg: str = ""
    file: str = ""
    function: str = ""
    line: int = 0


class ParameterValue(Message):
    """rcl_interfaces/msg/ParameterValue: one value, of the ``type`` it says."""

    ros_type: ClassVar[str] = "rcl_interfaces/msg/ParameterValue"
    NOT_SET: ClassVar[int] = 0
    BOOL: ClassVar[int] = 1
    INTEGER: ClassVar[int] = 2
    DOUBLE: ClassVar[int] = 3
    STRING: ClassVar[int] = 4
    type: int = 0
    bool_value: bool = False
    integer_value: int = 0
    double_value: float = 0.0
    string_value: str = ""
    byte_array_value: tuple[int, ...] = ()
    bool_array_value: tuple[bool, ...] = ()
    integer_array_value: tuple[int, ...] = ()
    double_array_value: tuple[float, ...] = ()
    string_array_value: tuple[str, ...] = ()


class Parameter(Message):
    """rcl_interfaces/msg/Parameter: a name and its value."""

    ros_type: ClassVar[str] = "rcl_interfaces/msg/Parameter"
    name: str = ""
    value: ParameterValue = ParameterValue()


class ParameterEvent(Message):
    """rcl_interfaces/msg/ParameterEvent: what a node's parameters became, on
    ``/parameter_events`` (a change made through ROS 2's parameter services)."""

    ros_type: ClassVar[str] = "rcl_interfaces/msg/ParameterEvent"
    stamp: Time = Time()
    node: str = ""
    """The node's fully qualified name, e.g. ``/nav``."""
    new_parameters: tuple[Parameter, ...] = ()
    changed_parameters: tuple[Parameter, ...] = ()
    deleted_parameters: tuple[Parameter, ...] = ()
