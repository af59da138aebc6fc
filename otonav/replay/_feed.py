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
from functools import partial
from typing import Any, NamedTuple

from otonav.actors._bridge import CLOCK, IMU, ODOM, TF
from otonav.msgs import Message
from otonav.replay._lazy import input_maker
from otonav.replay._recording import RecordedMessage
from otonav.runtime import Clock, Publisher, Reliability, VirtualTimeLoop
from otonav.runtime._timesource import tick_rate


class FeedSource:
    """A time source with no world (like :class:`~otonav.runtime.JumpSource`) that wakes
    the feeder ahead of every timer when time reaches the feeder's next instant."""

    __slots__ = ("_tick", "_wake", "_wake_tick", "ticks")

    def __init__(self, tick: float) -> None:
        if not tick > 0:
            raise ValueError(f"tick must be > 0 s, got {tick!r}")
        self._tick = tick
        self.ticks = 0
        self._wake: Callable[[], None] | None = None
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
            wake()

    def wake_at(self, tick: int, callback: Callable[[], None]) -> None:
        """Call ``callback()`` from ``advance()`` when time reaches ``tick``: inside the
        loop's select, before it moves the timers that fell due to the ready queue."""
        self._wake, self._wake_tick = callback, tick


@dataclass(frozen=True, slots=True)
class Settle:
    """A step of an instant: let ``actors`` run (they published here in the recording)."""

    actors: frozenset[str]


Step = RecordedMessage | Settle


class Instant(NamedTuple):
    """One instant the feeder works at. (A named tuple: a replay plans one per instant
    with input, 1,334 for the navigator on the acceptance recording.)"""

    tick: int
    steps: tuple[Step, ...]
    """Inputs to publish, in recorded order, with a Settle where actors ran in between."""
    last: bool = False
    holds: bool = False
    """Whether the actors' wake-ups must be held while the feeder works here."""
    after_idle: bool = False
    """Every replayed actor ran before the inputs (one Settle of all, first): deliver
    them when the loop is idle at this instant, no holding needed."""


def plan_instants(
    messages: Sequence[RecordedMessage],
    inputs: Collection[str],
    publishers_of: Mapping[str, Collection[str]],
    rate: float,
    actors: Collection[str] = (),
) -> list[Instant]:
    """Group the recording into the feeder's instants: those with input, plus the last
    one (so the replay runs to the recording's end). ``publishers_of`` maps each output
    topic to the replayed actors that publish it; outputs followed by input at the same
    instant (or ending the recording) become Settle steps. ``actors``: the names of all
    the replayed actors (an instant where all of them ran before its inputs is marked
    ``after_idle``)."""
    everyone = frozenset(actors)
    instants: list[Instant] = []
    tick = -1  # of the group being planned
    steps: list[Step] = []
    ran: set[str] = set()  # replayed actors that published since the last input
    settles = 0

    def close(last: bool) -> None:
        nonlocal settles
        if last:
            steps.append(Settle(frozenset(ran)))
            settles += 1
        if not steps:
            return
        first = steps[0]
        after_idle = (
            not last
            and settles == 1
            and isinstance(first, Settle)
            and bool(everyone)
            and first.actors == everyone
        )
        instants.append(Instant(tick, tuple(steps), last, last or settles > 0, after_idle))

    for message in messages:
        topic = message.topic
        publishers = publishers_of.get(topic)
        if publishers is None and topic not in inputs:
            continue
        at = round(message.time_ns * rate / 1e9)
        if at != tick:
            if tick >= 0:
                close(last=False)
            tick, steps, ran, settles = at, [], set(), 0
        if publishers is not None:
            ran.update(publishers)
            continue
        if ran:
            steps.append(Settle(frozenset(ran)))
            settles += 1
            ran = set()
        steps.append(message)
    if tick >= 0:
        close(last=True)
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
        self, gate: Gate, actor: str, *, wakes: Sequence[int] | None = None, rate: float
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


FLAT_LAYOUTS = (CLOCK, ODOM, TF, IMU)
"""The bridge's fixed layouts: its /clock, /odom, /tf and /imu are fed as the flat
messages it published (:func:`~otonav.replay._lazy.input_maker`)."""


class _Route(NamedTuple):
    publisher: Publisher[Any]
    make: Callable[[bytes], Message]
    subscriptions: Sequence[Any]
    reliable: tuple[Any, ...]


class Feeder:
    """Publishes the planned instants on ``publishers`` (topic -> publisher), each
    recorded message as :func:`~otonav.replay._lazy.input_maker` makes it: the bridge's
    flat message for its fixed-layout streams, otherwise a lazy one (decoded on first
    use).

    An instant that needs no holding (no replayed actor ran between two of its inputs)
    is delivered inline: from the time source's ``advance()``, in the loop's select, at
    the point where the feeder's own wake-up would have been queued ahead of every timer
    due then. That is the same order as a task step of the feeder at the head of the
    ready queue, without the task switch, future and loop iteration per instant (11 ms
    of a 113 ms navigator replay). Instants that hold, and a reliable mailbox that is
    full (the publisher would wait), go through the feeder's task.
    """

    def __init__(
        self,
        gate: Gate,
        source: FeedSource,
        instants: Sequence[Instant],
        publishers: Mapping[str, Publisher[Any]],
    ) -> None:
        self._gate = gate
        self._loop = gate.loop
        self._source = source
        self._instants = instants
        self._publishers = publishers
        self._rate = source.rate
        self._next = 0
        self._resume: asyncio.Future[tuple[int, int]] | None = None
        self.published = 0
        self._timer: asyncio.TimerHandle | None = None
        self.inline = 0
        """Instants delivered inline (the rest went through the task)."""
        self.batched = 0
        """Of those, instants delivered ahead of their tick (nothing could tell)."""
        self.after_idle = 0
        """Of those, instants delivered once their actors had run (``after_idle``)."""
        self._idle_watcher = self._at_idle  # one bound method, to know it among watchers
        self._routes: dict[str, _Route] = {}

    def _route(self, topic: str) -> _Route:
        """How to deliver on ``topic`` (~1 us less per recorded input than looking it
        all up per message): its publisher, a lazy-message maker, its subscriptions and
        the reliable ones among them (only those can make the feeder wait). Made again
        when the topic's subscriptions change (the topic replaces its list then)."""
        publisher = self._publishers[topic]
        subscriptions = publisher._topic.subscriptions
        route = self._routes[topic] = _Route(
            publisher,
            input_maker(publisher.msg_type, FLAT_LAYOUTS),
            subscriptions,
            tuple(s for s in subscriptions if s.qos.reliability is Reliability.RELIABLE),
        )
        return route

    def _route_of(self, topic: str) -> _Route:
        route = self._routes.get(topic)
        if route is None or route.subscriptions is not route.publisher._topic.subscriptions:
            route = self._route(topic)
        return route

    async def run(self) -> None:
        instants, source = self._instants, self._source
        index, start = 0, 0
        while index < len(instants):
            instant = instants[index]
            if start == 0 and instant.tick > source.ticks:
                if not instant.holds:
                    index, start = await self._inline_from(index)
                    continue
                await self._until(instant.tick)
            await self._instant(instant, start)
            index, start = index + 1, 0

    async def _instant(self, instant: Instant, start: int) -> None:
        """Publish ``instant``'s steps from ``start`` on, holding actors as planned."""
        gate = self._gate
        gate.holding = instant.holds
        idle = False  # the actors due now are parked (the loop went idle once)
        for step in instant.steps[start:]:
            if isinstance(step, Settle):
                if not idle:
                    await self._idle()
                    idle = True
                gate.release(step.actors)
                await self._idle()
                continue
            route = self._route_of(step.topic)
            await _publish(route.publisher, route.make(step.data))
            self.published += 1
        gate.holding = False
        if not instant.last:
            gate.release(None)  # the rest, in the order their timers fell due

    async def _inline_from(self, index: int) -> tuple[int, int]:
        """Deliver instants inline from ``index`` on; returns where the task takes over
        (instant, step), woken at that instant ahead of every timer due then."""
        self._resume = self._loop.create_future()
        self._arm(index)
        return await self._resume

    def _arm(self, index: int) -> None:
        self._next = index
        tick = self._instants[index].tick
        self._source.wake_at(tick, self._on_tick)
        # A timer at the instant, so the loop stops there even when no actor is due.
        self._timer = self._loop.call_at(tick / self._rate, _noop)

    def _on_tick(self) -> None:
        """From the source's ``advance()``: time reached instant ``_next``. Delivers it,
        and the instants after it that nothing can tell apart from it (see
        :meth:`_quiet_bound`); then arms the next one or hands over to the task."""
        index = self._next
        instant = self._instants[index]
        if instant.after_idle:
            # The actors due now run first (as recorded), then the inputs: at idle.
            self._loop.add_idle_watcher(self._idle_watcher)
            return
        if instant.holds:
            self._hand_over(index, 0)
            return
        blocked = self._deliver_now(instant)
        if blocked is not None:
            self._hand_over(index, blocked)
            return
        self.inline += 1
        self._go_on(index + 1)

    def _at_idle(self) -> bool:
        """An idle watcher: the actors of an ``after_idle`` instant have run."""
        index = self._next
        blocked = self._deliver_now(self._instants[index], 1)
        if blocked is not None:
            self._hand_over(index, blocked)
            return True
        self.inline += 1
        self.after_idle += 1
        self._go_on(index + 1)
        return True

    def _go_on(self, index: int) -> None:
        """Deliver the instants from ``index`` on that cannot be told apart from now
        (see :meth:`_quiet_bound`), then arm the next one, or hand over to the task at
        the end."""
        instants = self._instants
        bound = self._quiet_bound()
        if bound is not None:
            loop = self._loop
            resolution = loop.clock_resolution
            rate = self._rate
            while index < len(instants):
                following = instants[index]
                # A timer fires at tick T when its deadline < T / rate + resolution.
                if (
                    following.holds
                    or loop.has_ready()
                    or bound < (following.tick - 1) / rate + resolution
                    or not self._fits(following)
                ):
                    break
                # Early, but unobservable: no code runs before that instant.
                self._deliver_now(following)
                self.inline += 1
                self.batched += 1
                index += 1
        if index < len(instants):
            self._arm(index)
        else:
            self._hand_over(index, 0)

    def _quiet_bound(self) -> float | None:
        """Until when delivering instants ahead of their ticks is the same as at their
        ticks (None: not even the next one). An instant can go early when nothing woke
        from what was just delivered (the ready queue is empty: checked after each one),
        no idle watcher or worker thread can look, no timer but the feeder's own falls
        due before the instant's tick (the bound: the earliest other deadline), and its
        messages fit the mailboxes (:meth:`_fits`). Between two replayed wake-ups the
        navigator's replay gets four /odom instants: this saves their loop iterations
        (1342 -> 491, 9 ms of 96). Delivering changes none of this but the ready queue,
        so the bound holds while :meth:`_go_on` delivers.

        Asks the loop (its ready queue and timer heap, its watchers and holds)."""
        loop = self._loop
        if loop.holding or loop.has_idle_watchers(other_than=self._idle_watcher):
            return None
        return loop.deadline_after(self._timer)

    def _fits(self, instant: Instant) -> bool:
        """Whether the instant's messages fit its reliable mailboxes (none would wait)."""
        n = len(instant.steps)
        route_of = self._route_of
        for step in instant.steps:
            for s in route_of(step.topic).reliable:  # type: ignore[union-attr]
                if not s.has_room(n):
                    return False
        return True

    def _hand_over(self, index: int, step: int) -> None:
        resume, self._resume = self._resume, None
        assert resume is not None
        resume.set_result((index, step))

    def _deliver_now(self, instant: Instant, start: int = 0) -> int | None:
        """Offer the instant's messages from step ``start`` on to their mailboxes; the
        index of the first one a full reliable mailbox would make wait (None: all
        delivered)."""
        route_of = self._route_of
        steps = instant.steps
        for k in range(start, len(steps)):
            step = steps[k]
            assert not isinstance(step, Settle)
            publisher, make, subscriptions, reliable = route_of(step.topic)
            for s in reliable:
                if not s.has_room():
                    return k
            message = make(step.data)
            publisher.published += 1
            if publisher._history is not None:
                publisher._history.append(message)
            for subscription in subscriptions:
                subscription._offer(message)
            self.published += 1
        return None

    async def _until(self, tick: int) -> None:
        loop = self._loop
        future: asyncio.Future[None] = loop.create_future()
        self._source.wake_at(tick, partial(_resolve, future))
        # A timer at the instant, so the loop stops there even when no actor is due.
        handle = loop.call_at(tick / self._rate, _noop)
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


async def _publish(publisher: Publisher[Any], message: Message) -> None:
    """``publisher.publish(message)`` without its strict type check, which would decode
    a lazy message on the spot (the runtime's delivery, from the feeder)."""
    publisher.published += 1
    if publisher._history is not None:
        publisher._history.append(message)
    for subscription in publisher._topic.subscriptions:
        while not subscription._offer(message):
            await subscription._wait_for_room()


def _resolve(future: asyncio.Future[None]) -> None:
    # Called from the loop's select, before it moves due timers to the ready queue:
    # the feeder's task step is queued ahead of every one of them.
    if not future.done():
        future.set_result(None)


def _noop() -> None:
    pass
