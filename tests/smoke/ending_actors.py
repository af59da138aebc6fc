"""Users' nodes that end a run (``--actor ending_actors:NAME``): one raises at a known sim
instant, one deletes the run's out directory (``OTONAV_TEST_OUT``) then, one floods."""

from __future__ import annotations

import os
import shutil

from otonav.msgs import Twist
from otonav.runtime import Actor, Output, QoS

AT_S = 0.5


class Crashes(Actor):
    async def run(self) -> None:
        await self.clock.sleep(AT_S)
        raise RuntimeError("boom at half a second")


class DeletesTheOut(Actor):
    async def run(self) -> None:
        await self.clock.sleep(AT_S)
        shutil.rmtree(os.environ["OTONAV_TEST_OUT"])


class Floods(Actor):
    """Publishes in a tight loop and never sleeps: sim time never moves on."""

    out = Output("/flood", Twist, QoS(depth=10))

    async def run(self) -> None:
        message = Twist()
        while True:
            await self.out.publish(message)
