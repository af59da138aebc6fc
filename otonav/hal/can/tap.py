"""The CAN tap: publishes every frame the interface sent or received on ``/can/frames``
(``can_msgs/msg/Frame``), so a recording shows the bus like ``candump`` would.

It reads the interface's frame log (:meth:`CanBusInterface.take_frames`) and commands
nothing while the robot runs. The stack builder adds it when ``hal.kind`` is ``can``,
before the bridge: it stops after every actor that commands the wheels, and its
``on_stop`` sets the drives IDLE (:meth:`CanBusInterface.stop_drives`) and publishes
those last frames while the recorder still records.
"""

from __future__ import annotations

import contextlib
from typing import Final

import anyio

from otonav.hal.can.bus import RawFrame
from otonav.hal.can.interface import CanBusInterface
from otonav.msgs import Frame, Header, Time
from otonav.runtime import Actor, Bus, Output, QoS
from otonav.runtime.mailbox import Topic

__all__ = ["FRAMES_QOS", "FRAMES_TOPIC", "CanFrameTap"]

FRAMES_TOPIC: Final = "/can/frames"
FRAMES_QOS: Final = QoS(depth=200)
"""Reliable: a recording must hold every frame (~330 per simulated second)."""

_PAD: Final = tuple(bytes(8 - n) for n in range(9))


class CanFrameTap(Actor):
    """At ``rate_hz``, publish the frames logged since the last wake, in bus order,
    each stamped with the sim time it crossed the bus (the recording's log time is the
    publish time, up to one period later: 20 Hz costs a fifth of the wake-ups of 100 Hz
    and the frames keep their exact stamps)."""

    frames = Output(FRAMES_TOPIC, Frame, FRAMES_QOS)

    def __init__(self, hal: CanBusInterface, *, rate_hz: float = 20.0, name: str = "can_tap"):
        super().__init__(name)
        if not rate_hz > 0:
            raise ValueError(f"can tap rate must be > 0 Hz, got {rate_hz}")
        self.hal = hal
        self.rate_hz = rate_hz
        self._topic: Topic[Frame] | None = None
        self._stopping = False

    def on_wired(self, bus: Bus) -> None:
        self._topic = bus.topics[self.topic_of(CanFrameTap.frames)]

    async def run(self) -> None:
        rate = self.clock.rate(self.rate_hz)
        try:
            while True:
                await rate.sleep()
                await self.flush()
        except anyio.get_cancelled_exc_class():
            self._stopping = True  # the system stops us (a crash restarts without this)
            raise

    async def on_stop(self) -> None:
        # The stack builder lists the tap before the bridge, so it stops after every
        # actor that commands the wheels: the drives go IDLE here, and the recording
        # (still open: the recorder stops last) ends with those frames. Not when the
        # tap itself crashed (on_stop then precedes a restart, or the HAL's close).
        if self._stopping:
            self.hal.stop_drives()
        if self._topic is not None and not self._topic.subscriptions:
            self.hal.take_frames()
            return
        for t, raw in self.hal.take_frames():
            with contextlib.suppress(anyio.WouldBlock):
                header = Header.fast(stamp=Time.from_seconds(t), frame_id=self.hal.channel)
                self.frames.publish_nowait(_frame(header, raw))

    async def flush(self) -> None:
        if self._topic is not None and not self._topic.subscriptions:
            # Nobody listens (no recorder, no live view): building ~330 messages per
            # simulated second for nobody was ~3 % of a CAN run's CPU time.
            self.hal.take_frames()
            return
        channel = self.hal.channel
        publish, publish_nowait = self.frames.publish, self.frames.publish_nowait
        header: Header | None = None
        last = -1.0
        for t, raw in self.hal.take_frames():
            if header is None or t != last:  # frames of one instant share a header
                header, last = Header.fast(stamp=Time.from_seconds(t), frame_id=channel), t
            frame = _frame(header, raw)
            # No coroutine per frame while the mailboxes have room (the usual case:
            # ~15 frames per wake, a depth of 200); wait for room only when one is full.
            try:
                publish_nowait(frame)
            except anyio.WouldBlock:
                await publish(frame)


def _frame(header: Header, raw: RawFrame) -> Frame:
    data = raw.data
    n = len(data)
    return Frame.fast(
        header=header,
        id=raw.arbitration_id,
        is_rtr=raw.is_remote,
        is_extended=False,
        is_error=raw.is_error,
        dlc=n,
        data=tuple(data + _PAD[n]) if n <= 8 else tuple(data[:8]),
    )
