"""Nodes a user might write, for the launch tests (imported by file path)."""

from __future__ import annotations

from collections.abc import Mapping

from pydantic import BaseModel, Field

from otonav.msgs import LaserScan, Odometry, Twist
from otonav.runtime import SENSOR_DATA_QOS, Actor, Input, QoS, Reliability


class OdomCounter(Actor):
    """No parameters: counts /odom messages."""

    odom = Input("/odom", Odometry, SENSOR_DATA_QOS)

    def __init__(self, *, name: str | None = None, remap: Mapping[str, str] | None = None):
        super().__init__(name, remap=remap)
        self.count = 0

    async def run(self) -> None:
        async for _ in self.odom:
            self.count += 1


class Stubborn(Actor):
    """Declares parameters but its constructor does not take them."""

    class Params(BaseModel):
        gain: float = 1.0

    def __init__(self) -> None:
        super().__init__("stubborn")


NOT_AN_ACTOR = 42


class Tuned(Actor):
    """Parameters and no __init__ of its own: the base class takes them (issue 39)."""

    class Params(BaseModel):
        model_config = {"extra": "forbid"}
        gain: float = Field(1.0, gt=0.0)
        limits: dict[str, float] = {}


class RaisesInInit(Actor):
    """A constructor that raises, as a user's might (issue 41, case 11)."""

    def __init__(self, *, name: str | None = None, remap: Mapping[str, str] | None = None):
        super().__init__(name, remap=remap)
        raise RuntimeError("no device /dev/ttyUSB0")


class ScanAsTwist(Actor):
    """/scan typed as Twist: a wiring mistake (issue 39 item 3)."""

    scan = Input("/scan", Twist)


class ReliableScan(Actor):
    """A reliable subscriber on the best-effort /scan: a QoS mismatch."""

    scan = Input("/scan", LaserScan, QoS(reliability=Reliability.RELIABLE))
