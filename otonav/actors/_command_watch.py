"""A warning when nothing commands the robot: with ``nav.planner: external`` the stack
waits for the user's node on /cmd_vel_nav, and a run without one would idle silently."""

from __future__ import annotations

import anyio

from otonav.actors import _topics as topics
from otonav.msgs import Twist
from otonav.runtime import Actor, Input, QoS, Reliability

__all__ = ["EXTERNAL_COMMAND_WAIT", "CommandWatch"]

EXTERNAL_COMMAND_WAIT = 1.0
"""s of sim time the stack waits for a first command from an external planner."""

_ANY_PUBLISHER = QoS(Reliability.BEST_EFFORT, depth=1)  # matches any publisher's QoS


class CommandWatch(Actor):
    """Warns once (``self.log``: /rosout and stderr) when no message arrived on
    ``topic`` within ``within`` s of sim time; then stays quiet."""

    commands = Input(topics.CMD_VEL_NAV, Twist, _ANY_PUBLISHER)

    def __init__(
        self, topic: str = topics.CMD_VEL_NAV, *, within: float = EXTERNAL_COMMAND_WAIT
    ) -> None:
        super().__init__("command_watch", remap={topics.CMD_VEL_NAV: topic})
        self.topic = topic
        self.within = within
        self.warned = False

    async def run(self) -> None:
        with anyio.move_on_after(self.within):
            await self.commands.recv()
            return
        self.warned = True
        self.log.warning(
            f"no message on {self.topic} after {self.within:g} s: nav.planner is 'external', "
            f"so the robot waits for your node to publish geometry_msgs/Twist on {self.topic} "
            "(add it with --actor module:Class or the config's actors list, or set "
            "nav.planner: dwa for otonav's planner)"
        )
