"""Hardware abstraction layer: the robot as otonav sees it.

``otonav.hal.mujoco`` (the MuJoCo world) is not imported here, so importing the HAL's
types, interface and fake does not load MuJoCo.
"""

from otonav.hal._fake import FakeHardware
from otonav.hal._health import HardwareHealth, HealthLevel
from otonav.hal._interface import RobotHardwareInterface
from otonav.hal._types import (
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
