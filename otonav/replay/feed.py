"""Feeding recorded messages to live actors at their recorded instants, in their
recorded order relative to the actors' own wake-ups (docs/adr: replay ordering).

Two things decide what an actor computes at an instant: which messages are in its
mailboxes when it wakes, and so which of the messages published *at that same instant*
came before its wake-up. The recording shows that order only through the actor's own
outputs: the outputs it published at instant t sit, in the file, after the inputs it
could see and before those it could not. So the feeder

1. wakes at every instant that has recorded input, *before* any timer due then: the
   :class:`FeedSource` time source queues the feeder's wake-up from inside
   ``advance()``, which the loop calls before it collects the timers that fell due, so
   the wake-up is first in the ready queue whatever order the timers were set in;
2. publishes that instant's inputs in recorded order. Where the recording has outputs
   of replayed actors followed by more input at the same instant, those actors ran in
   between: the feeder holds every actor's wake-up due at this instant (each replayed
   actor sleeps on its own :class:`ReplayClock`, whose timers park the actor while the
   feeder holds the instant), releases the ones whose outputs come next, waits until
   the loop is idle, and goes on. At the end of the instant it releases the rest, in
   the order their timers fell due.

So with several replayed actors each one still wakes on the right side of each input
(the navigator and the base controller both wake at t = 0.3 s of the acceptance run,
the base before that instant's /odom and the navigator after it).

An actor that wakes and publishes nothing leaves no trace in the recording; at such an
instant the replay delivers the instant's inputs before it wakes. Every stack actor
publishes on every wake, so this is exact for them. Actors that sleep on the clock
(``self.clock.sleep_until``, ``rate``) are ordered this way; one that calls
``anyio.sleep`` directly is not held and runs when its timer falls due.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from otonav.record.cdr_decode import decode
from otonav.replay.recording import RecordedMessage
from otonav.runtime import Clock, Publisher, VirtualTimeLoop
from otonav.runtime.timesource import tick_rate


class FeedSource:
    """A time source with no world (like :class:`~otonav.runtime.JumpSource`) that wakes
    the feeder ahead of every timer when time reaches the feeder's next instant."""

    __slots__ = ("_tick", "_wake", "_wake_tick", "ticks")

    def __init__(self, tick: float) -> None:
        if not tick > 0:
            raise ValueError(f"tick must be > 0 s, got {tick!r}")
        self._tick = tick
        self.ticks = 0
        self._wake: asyncio.Future[None] | None = None
        self._wake_tick = 0

    @property
    def tick(self) -> float:
        return self._tick

    @property
    def rate(self) -> float:
        """Ticks per second, as the loop computes it (so tick k is at k / rate)."""
        return tick_rate(self._tick)

    def advance(self, n: int) -> None:
        self.ticks += n
        wake = self._wake
        if wake is not None and self.ticks >= self._wake_tick:
            self._wake = None
            # Called from the loop's select, before it moves due timers to the ready
            # queue: the feeder's task step is queued ahead of every one of them.
            if not wake.done():
                wake.set_result(None)

    def wake_at(self, tick: int, future: asyncio.Future[None]) -> None:
        self._wake, self._wake_tick = future, tick


@dataclass(frozen=True, slots=True)
class Settle:
    """A step of an instant: let ``actors`` run (they published here in the recording)."""

    actors: frozenset[str]


Step = RecordedMessage | Settle


@dataclass(frozen=True, slots=True)
class Instant:
    tick: int
    steps: tuple[Step, ...]
    """Inputs to publish, in recorded order, with a Settle where actors ran in between."""
    last: bool = False

    @property
    def holds(self) -> bool:
        """Whether the actors' wake-ups must be held while the feeder works here."""
        return self.last or any(isinstance(step, Settle) for step in self.steps)


def plan_instants(
    messages: Sequence[RecordedMessage],
    inputs: Collection[str],
    publishers_of: Mapping[str, Collection[str]],
    rate: float,
) -> list[Instant]:
    """Group the recording into the feeder's instants: those with input, plus the last
    one (so the replay runs to the recording's end). ``publishers_of`` maps each output
    topic to the replayed actors that publish it; outputs followed by input at the same
    instant (or ending the recording) become Settle steps."""
    groups: list[tuple[int, list[RecordedMessage]]] = []
    for message in messages:
        if message.topic not in inputs and message.topic not in publishers_of:
            continue
        tick = round(message.time_ns * rate / 1e9)
        if not groups or groups[-1][0] != tick:
            groups.append((tick, []))
        groups[-1][1].append(message)
    instants: list[Instant] = []
    for index, (tick, group) in enumerate(groups):
        last = index == len(groups) - 1
        steps: list[Step] = []
        ran: set[str] = set()  # replayed actors that published since the last input
        for message in group:
            if message.topic in publishers_of:
                ran.update(publishers_of[message.topic])
                continue
            if ran:
                steps.append(Settle(frozenset(ran)))
                ran = set()
            steps.append(message)
        if last:
            steps.append(Settle(frozenset(ran)))
        if steps:
            instants.append(Instant(tick, tuple(steps), last))
    return instants


class Gate:
    """Holds the replayed actors' timer wake-ups while the feeder orders an instant."""

    def __init__(self, loop: VirtualTimeLoop) -> None:
        self.loop = loop
        self.holding = False
        self.parked: list[tuple[str, asyncio.Future[None]]] = []

    def due(self, actor: str, future: asyncio.Future[None]) -> None:
        if future.done():
            return
        if self.holding:
            self.parked.append((actor, future))
        else:
            future.set_result(None)

    def release(self, actors: Collection[str] | None) -> None:
        """Wake the parked actors among ``actors`` (all when None), in parking order."""
        keep: list[tuple[str, asyncio.Future[None]]] = []
        for actor, future in self.parked:
            if actors is None or actor in actors:
                if not future.done():
                    future.set_result(None)
            else:
                keep.append((actor, future))
        self.parked = keep


class ReplayClock(Clock):
    """Sim time for one replayed actor: like the virtual clock, but its timers pass
    through the :class:`Gate` so the feeder can order them against the inputs.

    ``wakes`` (ticks, sorted): wake the actor at the recorded instants instead of its
    own deadlines -- for a recording made in real time, where an actor asleep until t
    woke when the world had caught up with the wall clock, a little after t. Each sleep
    then ends at the actor's next recorded wake-up (the instants its outputs were
    published at, in order); past the last one the actor sleeps for good.
    """

    def __init__(
        self, gate: Gate, actor: str, *, wakes: Sequence[int] | None = None, rate: float = 1.0
    ) -> None:
        self._gate = gate
        self._loop = gate.loop
        self._actor = actor
        self._wakes = wakes
        self._rate = rate
        self._next = 0

    def now(self) -> float:
        return self._loop.time()

    def to_loop_time(self, sim_time: float) -> float:
        return sim_time

    def watch(self, check: Callable[[], bool]) -> Callable[[], None]:
        return self._loop.add_idle_watcher(check)

    async def sleep_until(self, sim_time: float) -> None:
        loop = self._loop
        if sim_time <= loop.time() and self._wakes is None:
            await asyncio.sleep(0)
            return
        future: asyncio.Future[None] = loop.create_future()
        if self._wakes is not None:
            # Follow the recorded wake-ups in order, whatever instant the actor asks for:
            # in real time an actor can wake twice at one instant (its sleep until a
            # time the world had already passed returned at once), which a replay, where
            # time stands still while it computes, would not ask for.
            now = round(loop.time() * self._rate)
            wakes, index = self._wakes, self._next
            while index < len(wakes) and wakes[index] < now:
                index += 1
            if index == len(wakes):
                await future  # never resolved: the system stops it at the end
            self._next = index + 1
            sim_time = wakes[index] / self._rate
        handle = loop.call_at(sim_time, self._gate.due, self._actor, future)
        try:
            await future
        finally:
            handle.cancel()


class Feeder:
    """Publishes the planned instants on ``publishers`` (topic -> publisher); calls
    ``after_instant()`` once each instant's inputs are out (to drain the outputs)."""

    def __init__(
        self,
        gate: Gate,
        source: FeedSource,
        instants: Sequence[Instant],
        publishers: Mapping[str, Publisher[Any]],
        after_instant: Callable[[], None],
    ) -> None:
        self._gate = gate
        self._loop = gate.loop
        self._source = source
        self._instants = instants
        self._publishers = publishers
        self._after_instant = after_instant
        self.published = 0

    async def run(self) -> None:
        source, publishers, gate = self._source, self._publishers, self._gate
        for instant in self._instants:
            if instant.tick > source.ticks:
                await self._until(instant.tick)
            gate.holding = instant.holds
            idle = False  # the actors due now are parked (the loop went idle once)
            for step in instant.steps:
                if isinstance(step, Settle):
                    if not idle:
                        await self._idle()
                        idle = True
                    gate.release(step.actors)
                    await self._idle()
                    continue
                publisher = publishers[step.topic]
                await publisher.publish(decode(publisher.msg_type, step.data))
                self.published += 1
            gate.holding = False
            if not instant.last:
                gate.release(None)  # the rest, in the order their timers fell due
            self._after_instant()

    async def _until(self, tick: int) -> None:
        loop = self._loop
        future: asyncio.Future[None] = loop.create_future()
        self._source.wake_at(tick, future)
        # A timer at the instant, so the loop stops there even when no actor is due.
        handle = loop.call_at(tick / self._source.rate, _noop)
        try:
            await future
        finally:
            handle.cancel()

    async def _idle(self) -> None:
        """Wait until nothing is ready at this instant (every woken actor has run)."""
        future: asyncio.Future[None] = self._loop.create_future()

        def idle() -> bool:
            if not future.done():
                future.set_result(None)
            return True

        self._loop.add_idle_watcher(idle)
        await future


def _noop() -> None:
    pass
