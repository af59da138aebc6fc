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
