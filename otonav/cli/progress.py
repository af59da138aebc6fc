"""The live progress line of ``otonav run`` on a terminal: sim time, real-time factor,
distance to goal, nav state. It only prints: nothing it does reaches the robot or the
recording, so runs with and without it are identical."""

from __future__ import annotations

import sys
import time
from typing import TextIO

from otonav.actors import topics
from otonav.msgs import NavState
from otonav.runtime import Actor, Input, QoS, Reliability


class ProgressLine(Actor):
    """Every ``period`` s of sim time, redraw one line if ``min_wall`` s of wall time
    passed since the last redraw (a UI reads the wall clock; robot actors never do)."""

    state = Input(topics.NAV_STATE, NavState, QoS(Reliability.BEST_EFFORT, depth=1))

    def __init__(
        self, stream: TextIO = sys.stderr, *, period: float = 0.1, min_wall: float = 0.1
    ) -> None:
        super().__init__("progress")
        self.stream = stream
        self.period = period
        self.min_wall = min_wall
        self._wall0 = time.perf_counter()
        self._last_draw = -1.0
        self._latest: NavState | None = None

    async def run(self) -> None:
        rate = self.clock.rate(1.0 / self.period)
        while True:
            await rate.sleep()
            self._latest = self.state.take_latest() or self._latest
            wall = time.perf_counter()
            if wall - self._last_draw >= self.min_wall:
                self._last_draw = wall
                self._draw(self.clock.now(), wall - self._wall0)

    def _draw(self, sim: float, wall: float) -> None:
        state = self._latest
        rtf = sim / wall if wall > 0 else 0.0
        nav = f"{state.distance_to_goal:5.2f} m to goal | {state.state}" if state else "starting"
        self.stream.write(f"\r  sim {sim:6.2f} s | {rtf:5.0f}x real time | {nav}   ")
        self.stream.flush()

    async def on_stop(self) -> None:
        self.stream.write("\r" + " " * 72 + "\r")
        self.stream.flush()
