"""The wheels over a CAN bus (ODrive CAN Simple), through python-can.

- ``protocol``: ids and payloads (``struct``), no python-can;
- ``bus``: the python-can boundary, the only module importing ``can``;
- ``monitor``: startup, fault detection and recovery, pure logic on sim time;
- ``interface``: :class:`CanBusInterface`, a ``RobotHardwareInterface``;
- ``tap``: the actor that publishes the raw frames (``can_msgs/msg/Frame``).
"""

from otonav.hal.can._bus import BusError, CanEndpoint, RawFrame, open_endpoint
from otonav.hal.can._interface import BusPeer, CanBusInterface, WheelAxis
from otonav.hal.can._monitor import DriveMonitor, MonitorLimits, Phase

__all__ = (
    "BusError",
    "BusPeer",
    "CanBusInterface",
    "CanEndpoint",
    "DriveMonitor",
    "MonitorLimits",
    "Phase",
    "RawFrame",
    "WheelAxis",
    "open_endpoint",
)
