"""Real time with a bounded catch-up: the clock a live stack on a host's loop uses."""

from __future__ import annotations

import math

import anyio
import anyio.to_thread

from otonav.runtime import (
    RealTimeClock,
    TimeSource,
)


class PacedClock(RealTimeClock):
    """:class:`~otonav.runtime.RealTimeClock` whose advances step at most
    ``max_step_batch`` seconds of sim time each.

    Run :meth:`pace` alongside (the live stack does): it consults the clock every half
    batch of wall time, so the world follows the wall clock in small steps even while
    every actor sleeps. A longer gap then means the loop was held up (a stalled host, a
    slow callback): the excess is dropped rather than stepped in one burst, sim time
    slips behind the wall clock by it (:attr:`slip_s`) and follows it again from there.
    """

    def __init__(
        self, source: TimeSource, *, scale: float = 1.0, max_step_batch: float = 0.05
    ) -> None:
        super().__init__(source, scale=scale)
        if not max_step_batch > 0:
            raise ValueError(f"max_step_batch must be > 0 s, got {max_step_batch!r}")
        self.max_batch_ticks = max(1, math.floor(max_step_batch * self._rate + 1e-9))
        self.slipped_ticks = 0

    @property
    def slip_s(self) -> float:
        """Sim seconds dropped so far (how far sim time fell behind the scaled wall)."""
        return self.slipped_ticks / self._rate

    async def pace(self) -> None:
        """Step the world to the wall clock every half batch (wall time), forever."""
        period = self.max_batch_ticks / self._rate / self.scale / 2
        while True:
            await anyio.sleep(period)
            self._follow_wall()

    def _follow_wall(self) -> None:
        wall = self._wall()
        assert self._wall0 is not None
        ticks_per_wall_s = self.scale * self._rate
        target = math.floor((wall - self._wall0) * ticks_per_wall_s + 1e-9)
        excess = target - self._ticks - self.max_batch_ticks
        if excess > 0:
            # Slip: from now on the wall clock maps to sim time `excess` ticks later.
            self._wall0 += excess / ticks_per_wall_s
            self.slipped_ticks += excess
            target -= excess
        self._advance_to(target)

    async def sleep_until(self, sim_time: float) -> None:
        goal = math.ceil(sim_time * self._rate - 1e-9)
        while True:
            await anyio.sleep_until(self.to_loop_time(sim_time))
            self._follow_wall()
            if self._ticks >= goal:
                return
            if goal - self._ticks <= 1:
                # The timer fired a hair early: the world still reaches the asked instant.
                self._advance_to(goal)
                return
            # Sim time slipped while we slept: the instant is later on the wall clock now.
