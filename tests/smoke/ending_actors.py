"""Users' nodes that end a run at a known sim instant (``--actor ending_actors:NAME``):
one raises, one deletes the run's out directory (``OTONAV_TEST_OUT``)."""

from __future__ import annotations

import os
import shutil

from otonav.runtime import Actor

AT_S = 0.5


class Crashes(Actor):
    async def run(self) -> None:
        await self.clock.sleep(AT_S)
        raise RuntimeError("boom at half a second")


class DeletesTheOut(Actor):
    async def run(self) -> None:
        await self.clock.sleep(AT_S)
        shutil.rmtree(os.environ["OTONAV_TEST_OUT"])
