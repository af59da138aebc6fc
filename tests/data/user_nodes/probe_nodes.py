"""Nodes a user might write, for the launch tests (imported by file path)."""

from __future__ import annotations

from collections.abc import Mapping

from pydantic import BaseModel

from otonav.msgs import Odometry
from otonav.runtime import SENSOR_DATA_QOS, Actor, Input


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
