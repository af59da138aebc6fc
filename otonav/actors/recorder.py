"""The recorder: every topic (or a chosen set) into one MCAP file, in publish order."""

from __future__ import annotations

from collections.abc import Collection

from otonav.record.writer import RecordingWriter
from otonav.runtime import Actor, Bus
from otonav.runtime.funnel import Funnel


class Recorder(Actor):
    """Taps every topic as it appears (like ``ros2 bag record -a``) through one funnel,
    so the file keeps the global publish order and each message's sim instant. On stop
    it drains what is left; the file's owner finishes it.

    It writes every ``period`` s of sim time what was published since (the funnel
    stamps each message when it is published, so the file is the same bytes whatever the
    period). Waking once per 10 ms instant instead cost ~10 us per wake: 13 % of the
    recorder's cost in a 30 s run. A SIGKILL can lose up to ``period`` s more than the
    last chunk; every other exit drains the funnel first.
    """

    def __init__(
        self,
        writer: RecordingWriter,
        *,
        topics: Collection[str] | None = None,
        period: float = 0.1,
        name: str = "recorder",
    ) -> None:
        super().__init__(name)
        if not period > 0:
            raise ValueError(f"recorder period must be > 0 s, got {period}")
        self.period = period
        self.writer = writer
        self._wanted = frozenset(topics) if topics is not None else None
        self._funnel: Funnel | None = None

    def on_wired(self, bus: Bus) -> None:
        wanted = self._wanted
        self._funnel = Funnel(
            bus,
            self.name,
            self._now,
            wanted=(lambda name: name in wanted) if wanted is not None else (lambda _n: True),
        )

    def _now(self) -> float:
        # Until the System hands out clocks (a latched message replayed at wiring), the
        # time is the start, 0; then use the clock's own bound method (one call less
        # per recorded message).
        if self._otonav_clock is None:
            return 0.0
        now = self._otonav_clock.now
        if self._funnel is not None:
            self._funnel._now = now
        return now()

    @property
    def funnel(self) -> Funnel:
        if self._funnel is None:
            raise RuntimeError("the recorder records once a System has wired it")
        return self._funnel

    async def run(self) -> None:
        rate = self.clock.rate(1.0 / self.period)
        while True:
            await rate.sleep()
            self.drain()

    def drain(self) -> None:
        """Write everything still queued (on stop, and before a verdict is appended)."""
        funnel, writer = self.funnel, self.writer
        while (delivery := funnel.try_recv()) is not None:
            if not writer.finished:
                writer.write(delivery.topic, delivery.message, delivery.time)

    async def on_stop(self) -> None:
        self.drain()
