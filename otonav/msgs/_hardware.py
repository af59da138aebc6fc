"""Hardware-facing messages: CAN frames, diagnostics, the hardware status."""

from __future__ import annotations

from typing import ClassVar

from otonav.msgs._base import Message
from otonav.msgs._std import Header


class Frame(Message):
    """can_msgs/msg/Frame: one classic CAN frame as seen on the bus (sent or received).

    ``header.stamp`` is the sim time it crossed the bus, ``header.frame_id`` the channel.
    """

    ros_type: ClassVar[str] = "can_msgs/msg/Frame"
    header: Header = Header()
    id: int = 0
    """11-bit arbitration id (ODrive CAN Simple: node_id << 5 | cmd)."""
    is_rtr: bool = False
    is_extended: bool = False
    is_error: bool = False
    dlc: int = 0
    """Number of valid bytes in ``data`` (0..8)."""
    data: tuple[int, ...] = (0,) * 8
    """Always 8 bytes; only the first ``dlc`` are the payload."""


class KeyValue(Message):
    """diagnostic_msgs/msg/KeyValue."""

    ros_type: ClassVar[str] = "diagnostic_msgs/msg/KeyValue"
    key: str = ""
    value: str = ""


class DiagnosticStatus(Message):
    """diagnostic_msgs/msg/DiagnosticStatus: one component's state."""

    ros_type: ClassVar[str] = "diagnostic_msgs/msg/DiagnosticStatus"
    OK: ClassVar[int] = 0
    WARN: ClassVar[int] = 1
    ERROR: ClassVar[int] = 2
    STALE: ClassVar[int] = 3
    level: int = 0
    name: str = ""
    message: str = ""
    hardware_id: str = ""
    values: tuple[KeyValue, ...] = ()


class DiagnosticArray(Message):
    """diagnostic_msgs/msg/DiagnosticArray: what ``/diagnostics`` carries."""

    ros_type: ClassVar[str] = "diagnostic_msgs/msg/DiagnosticArray"
    header: Header = Header()
    status: tuple[DiagnosticStatus, ...] = ()


class HardwareStatus(Message):
    """The HAL's health for the control loop (bridge -> base, navigator): published
    when it changes, latched. ``level`` as DiagnosticStatus; ERROR or worse is a fault."""

    ros_type: ClassVar[str] = "otonav_msgs/msg/HardwareStatus"
    header: Header = Header()
    level: int = 0
    ready: bool = True
    """The hardware takes commands (false while starting or recovering)."""
    fault: str = ""
    """Short fault kind (``heartbeat_lost``, ``axis_error``, ...); empty when none."""
    message: str = ""

    @property
    def drivable(self) -> bool:
        """Wheel commands may be non-zero."""
        return self.ready and self.level < DiagnosticStatus.ERROR

    @property
    def faulted(self) -> bool:
        return self.level >= DiagnosticStatus.ERROR
