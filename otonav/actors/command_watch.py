"""A warning when nothing commands the robot: with ``nav.planner: external`` the stack
waits for the user's node on /cmd_vel_nav, and a run without one would idle silently."""

from __future__ import annotations

import contextlib
import logging

import anyio

from otonav.actors import topics
from otonav.msgs import Log, Time, Twist
from otonav.runtime import Actor, Input, Output, QoS, Reliability

__all__ = ["EXTERNAL_COMMAND_WAIT", "CommandWatch"]

EXTERNAL_COMMAND_WAIT = 1.0
"""s of sim time the stack waits for a first command from an external planner."""

_LOG = logging.getLogger("otonav")
_ANY_PUBLISHER = QoS(Reliability.BEST_EFFORT, depth=1)  # matches any publisher's QoS


class CommandWatch(Actor):
    """Warns once, on /rosout and through :mod:`logging` (stderr), when no message
    arrived on ``topic`` within ``within`` s of sim time; then stays quiet."""

    commands = Input(topics.CMD_VEL_NAV, Twist, _ANY_PUBLISHER)
    rosout = Output(topics.ROSOUT, Log, topics.ROSOUT_QOS)

    def __init__(self, topic: str = topics.CMD_VEL_NAV, *, within: float = 1.0) -> None:
        super().__init__("command_watch", remap={topics.CMD_VEL_NAV: topic})
        self.topic = topic
        self.within = within
        self.warned = False

    async def run(self) -> None:
        with anyio.move_on_after(self.within):
            await self.commands.recv()
            return
        self.warned = True
        text = (
            f"no message on {self.topic} after {self.within:g} s: nav.planner is 'external', "
            f"so the robot waits for your node to publish geometry_msgs/Twist on {self.topic} "
            "(add it with --actor module:Class or the config's actors list, or set "
            "nav.planner: dwa for otonav's planner)"
        )
        _LOG.warning("%s", text)
        with contextlib.suppress(anyio.WouldBlock):
            self.rosout.publish_nowait(
                Log.fast(
                    stamp=Time.from_seconds(self.clock.now()),
                    level=Log.WARN,
                    name=self.name,
                    msg=text,
                    file="",
                    function="",
                    line=0,
                )
            )
