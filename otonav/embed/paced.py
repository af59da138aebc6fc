"""The clock a live stack on a host's loop uses: real time with a bounded catch-up."""

from __future__ import annotations

from otonav.runtime import RealTimeClock, TimeSource
from otonav.runtime.clock import MAX_STEP_BATCH


class PacedClock(RealTimeClock):
    """:class:`~otonav.runtime.RealTimeClock` with a 0.05 s catch-up cap by default: one
    advance never blocks the host's loop for more than a small physics batch (the live
    stack also runs :meth:`pace`)."""

    def __init__(
        self, source: TimeSource, *, scale: float = 1.0, max_step_batch: float = MAX_STEP_BATCH
    ) -> None:
        super().__init__(source, scale=scale, max_step_batch=max_step_batch)
