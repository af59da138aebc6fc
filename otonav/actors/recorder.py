"""The recorder: every topic (or a chosen set) into one MCAP file, in publish order."""

from __future__ import annotations

from collections.abc import Collection

from otonav.record.writer import RecordingWriter
from otonav.runtime import Actor, Bus
from otonav.runtime.funnel import Funnel


class Recorder(Actor):
    """Taps every topic as it appears (like ``ros2 bag record -a``) through one funnel,
    so the file keeps the global publish order and each message's sim instant. On stop
    it drains what is left; the file's owner finishes it."""

    def __init__(
        self,
        writer: RecordingWriter,
        *,
        topics: Collection[str] | None = None,
        name: str = "recorder",
    ) -> None:
        super().__init__(name)
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
        # Until the System hands out clocks, ask each time; then use the clock's own
        # bound method (one call less per recorded message).
        now = self.clock.now
        if self._funnel is not None:
            self._funnel._now = now
        return now()

    @property
    def funnel(self) -> Funnel:
        if self._funnel is None:
            raise RuntimeError("the recorder records once a System has wired it")
        return self._funnel

    async def run(self) -> None:
        funnel, write = self.funnel, self.writer.write
        while True:
            first = await funnel.recv()
            write(first.topic, first.message, first.time)
            # Everything published at this instant is queued: write it without
            # going back to the loop for each message.
            while (more := funnel.try_recv()) is not None:
                write(more.topic, more.message, more.time)

    def drain(self) -> None:
        """Write everything still queued (on stop, and before a verdict is appended)."""
        funnel, writer = self.funnel, self.writer
        while (delivery := funnel.try_recv()) is not None:
            if not writer.finished:
                writer.write(delivery.topic, delivery.message, delivery.time)

    async def on_stop(self) -> None:
        self.drain()
