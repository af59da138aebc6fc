"""Hardware abstraction layer: the robot as otonav sees it.

``otonav.hal.mujoco`` (the MuJoCo world) is not imported here, so importing the HAL's
types, interface and fake does not load MuJoCo.
"""

import warnings as _warnings

from otonav.hal.fake import FakeHardware
from otonav.hal.health import HardwareHealth, HealthLevel
from otonav.hal.interface import RobotHardwareInterface
from otonav.hal.types import (
    BoxObstacle,
    GroundTruth,
    ImuSample,
    PolygonObstacle,
    RangeScan,
    RobotGeometry,
    RoundObstacle,
    WheelSetpoint,
    WheelState,
)

__all__ = (
    "BoxObstacle",
    "FakeHardware",
    "GroundTruth",
    "HardwareHealth",
    "HealthLevel",
    "ImuSample",
    "PolygonObstacle",
    "RangeScan",
    "RobotGeometry",
    "RobotHardwareInterface",
    "RoundObstacle",
    "WheelSetpoint",
    "WheelState",
)


def __getattr__(name: str) -> object:
    if name == "WheelCommand":  # renamed (ADR 0056): msgs.WheelCommand is the message
        _warnings.warn(
            "otonav.hal.WheelCommand is now otonav.hal.WheelSetpoint "
            "(otonav.msgs.WheelCommand is the stamped message on /wheel_cmd)",
            DeprecationWarning,
            stacklevel=2,
        )
        return WheelSetpoint
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
