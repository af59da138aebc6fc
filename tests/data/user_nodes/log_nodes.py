"""Nodes that log as an rclpy node does, and one that crashes in its own code."""

from __future__ import annotations

from pydantic import BaseModel

from otonav.runtime import Actor


class Talker(Actor):
    """Logs at every level, at known sim times."""

    class Params(BaseModel):
        at: float = 1.0

    params: Params  # set by Actor.__init__; the annotation is for mypy

    async def run(self) -> None:
        self.log.info("starting, warning at %.1f s", self.params.at)
        await self.clock.sleep_until(self.params.at)
        self.log.warning("battery low: %d %%", 12)
        self.log.debug("a detail only -v shows")
        await self.clock.sleep_until(2 * self.params.at)
        self.log.error("lost the drive")


class Crasher(Actor):
    """Raises in run(), from a helper of its own."""

    async def run(self) -> None:
        await self.clock.sleep_until(0.5)
        _helper()


def _helper() -> None:
    raise ValueError("node exploded")
