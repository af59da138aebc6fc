"""The time mode of a run, as a value (ADR 0082).

Every way of starting a stack takes ``time=``: :class:`Virtual` (the default: sim time
is the loop's time and runs as fast as the world computes) or :class:`RealTime` (sim
time follows the wall clock times ``scale``). One spelling for the CLI's ``--realtime``
/ ``--scale``, ``run_scenario``, ``running_stack``, ``open_live_stack`` and
``StackSession``, as anyio has one ``run(..., backend=...)``. Lockstep with external
ROS 2 nodes is virtual time whose instants wait for the nodes' answers: the ``ros2``
section of the stack config asks for it (``ros2.lockstep``), not a third clock.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from otonav.limits import check_scale
from otonav.runtime._clock import MAX_STEP_BATCH, REAL_TIME_SCALE, RealTimeClock
from otonav.runtime._timesource import TimeSource

__all__ = ["RealTime", "TimeMode", "Virtual"]


@dataclass(frozen=True, slots=True)
class Virtual:
    """Sim time is the running :class:`~otonav.runtime.VirtualTimeLoop`'s time: the world
    is the loop's time source and each instant runs as fast as it computes."""

    def clock(self, source: TimeSource) -> None:
        """No clock of its own: the loop is the clock."""
        return None


@dataclass(frozen=True, slots=True)
class RealTime:
    """Sim time follows the wall clock times ``scale`` on any (stock) loop; one advance
    steps at most ``max_step_batch`` s of sim time (after a stall sim time slips behind
    instead of catching up in a burst; None: no cap)."""

    scale: float = REAL_TIME_SCALE
    max_step_batch: float | None = MAX_STEP_BATCH

    def __post_init__(self) -> None:
        problem = check_scale(self.scale, "RealTime(scale=...)")
        if problem is not None:
            raise ValueError(problem)
        batch = self.max_step_batch
        if batch is not None and not (math.isfinite(batch) and batch > 0):
            raise ValueError(f"RealTime(max_step_batch={batch!r}): must be > 0 s, or None")

    def clock(self, source: TimeSource) -> RealTimeClock:
        """The clock that paces ``source`` to the wall clock."""
        return RealTimeClock(source, scale=self.scale, max_step_batch=self.max_step_batch)


TimeMode = Virtual | RealTime
"""What ``time=`` takes."""
