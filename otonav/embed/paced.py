"""Deprecated: :class:`PacedClock` is :class:`~otonav.runtime.RealTimeClock` (ADR 0055)."""

from __future__ import annotations

import warnings

from otonav.runtime import MAX_STEP_BATCH, RealTimeClock, TimeSource


class PacedClock(RealTimeClock):
    """Deprecated alias of :class:`~otonav.runtime.RealTimeClock`, which now has the same
    0.05 s catch-up cap (:data:`~otonav.runtime.MAX_STEP_BATCH`) by default. Kept so
    code written against otonav.embed keeps working; constructing one warns."""

    def __init__(
        self, source: TimeSource, *, scale: float = 1.0, max_step_batch: float = MAX_STEP_BATCH
    ) -> None:
        warnings.warn(
            "otonav.embed.PacedClock is deprecated: use otonav.runtime.RealTimeClock "
            "(the same clock, with the same max_step_batch default)",
            DeprecationWarning,
            stacklevel=2,
        )
        super().__init__(source, scale=scale, max_step_batch=max_step_batch)
