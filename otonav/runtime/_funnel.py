"""A funnel: one mailbox fed by many topics, keeping the global publish order.

A recorder wants every message of every topic in the order it was published, stamped
with the instant it was published. Each topic gets an ordinary-looking subscription (it
shows in the graph with its counters) whose deliveries go into the funnel's one queue.
Reliable: when the funnel is full, publishers wait (backpressure); nothing is lost.

The reader (the recorder) drains on its own period, and asks to be woken when the queue
reaches its high-water mark (half the depth): it then drains in the same instant, so in
virtual time a publisher never waits while sim time (and the world) runs on. Only a
burst larger than the room left waits, within its instant; such waits are counted
(:meth:`Funnel.statistics`) and the first on each topic is logged.
"""

from __future__ import annotations

import logging
from collections import deque
from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

from otonav.runtime._mailbox import Bus, Endpoint, Subscription, Topic
from otonav.runtime._qos import QoS, Reliability

log = logging.getLogger("otonav.runtime._funnel")


class FunnelStatistics(NamedTuple):
    """Counters of a funnel."""

    queued: int
    """Deliveries waiting now."""
    depth: int
    """Capacity; a publisher waits when the queue is this long."""
    high_water: int
    """Queue length at which the reader is woken."""
    high_water_wakes: int
    """Times the reader was woken early by the high-water mark."""
    blocked_publishes: int
    """Publishes that found the funnel full and waited for room."""
    blocked_topics: tuple[str, ...]
    """Topics of those publishes, sorted."""


class Delivery(NamedTuple):
    topic: str
    time: float
    message: Any


DEPTH = 10_000
"""Messages a funnel holds before its publishers wait (the recorder's default)."""


# The loosest request: matches every publisher (ROS 2 rules), so tapping a topic can
# never make wiring fail. Nothing is dropped anyway: the funnel applies backpressure.
TAP_QOS = QoS(Reliability.BEST_EFFORT, depth=1)


class _Tap(Subscription[Any]):
    __slots__ = ("_blocked_at", "_funnel")

    def __init__(self, funnel: Funnel, topic: Topic[Any], endpoint: Endpoint) -> None:
        super().__init__(topic.name, topic.msg_type, TAP_QOS, endpoint)
        self._funnel = funnel
        self._blocked_at: float | None = None

    def _offer(self, message: Any) -> bool:
        funnel = self._funnel
        queue = funnel._queue
        if len(queue) >= funnel.depth:
            # Full: the publisher waits. Remember when it published, so the message is
            # stamped with that instant, not with the instant room was found.
            if self._blocked_at is None:
                self._blocked_at = funnel._now()
                funnel._note_blocked(self.topic, self._blocked_at)
            funnel._blocked.append(self)  # one entry per waiting publisher
            funnel._wake_reader()
            return False
        stamp, self._blocked_at = self._blocked_at, None
        # A plain tuple (a Delivery is made only by try_recv): 0.3 us less per message.
        queue.append((self.topic, funnel._now() if stamp is None else stamp, message))
        self.received += 1
        if len(queue) >= funnel.high_water and funnel._on_high_water is not None:
            funnel._wake_reader()
        return True

    def _full(self) -> bool:
        return len(self._funnel._queue) >= self._funnel.depth

    def _has_room(self, n: int) -> bool:
        return len(self._funnel._queue) + n <= self._funnel.depth

    def _offer_all(self, messages: Sequence[Any]) -> None:
        """:meth:`_offer` each of ``messages`` (they fit: :meth:`_has_room`): one
        ``extend``, all stamped with this instant, the reader woken once if the queue
        reached its high-water mark (waking it is a request to drain, never a drain)."""
        if self._blocked_at is not None and messages:  # a publisher gave up waiting
            self._offer(messages[0])
            messages = messages[1:]
        funnel = self._funnel
        queue = funnel._queue
        topic, now = self.topic, funnel._now()
        queue.extend([(topic, now, message) for message in messages])
        self.received += len(messages)
        if len(queue) >= funnel.high_water and funnel._on_high_water is not None:
            funnel._wake_reader()


class Funnel:
    """Taps topics of ``bus`` (all, or those ``wanted`` accepts), now and as they appear."""

    def __init__(
        self,
        bus: Bus,
        owner: str,
        now: Callable[[], float],
        *,
        wanted: Callable[[str], bool] = lambda _name: True,
        depth: int = DEPTH,
        high_water: int | None = None,
    ) -> None:
        if depth < 1:
            raise ValueError(f"funnel depth must be >= 1, got {depth}")
        self.depth = depth
        self.high_water = max(1, depth // 2) if high_water is None else high_water
        if not 1 <= self.high_water <= depth:
            raise ValueError(f"high_water must be in 1..depth ({depth}), got {high_water}")
        self._on_high_water: Callable[[], object] | None = None
        self.high_water_wakes = 0
        self.blocked_publishes = 0
        self._blocked_topics: set[str] = set()
        self._owner = owner
        self._now = now
        self._wanted = wanted
        self._queue: deque[tuple[str, float, Any]] = deque()
        self._blocked: deque[_Tap] = deque()
        self.taps: dict[str, _Tap] = {}
        for topic in list(bus.topics.values()):
            self._tap(topic)
        bus.add_topic_listener(self._tap)

    def use_clock(self, now: Callable[[], float]) -> None:
        """Stamp deliveries with ``now()`` from here on (e.g. a clock's bound ``now``,
        once the System hands out clocks)."""
        self._now = now

    def _tap(self, topic: Topic[Any]) -> None:
        if topic.name in self.taps or not self._wanted(topic.name):
            return
        tap = _Tap(self, topic, Endpoint(self._owner, topic.name))
        self.taps[topic.name] = tap
        topic.add_subscription(tap)
        # A transient-local publisher may already hold history: record it too.
        for publisher in topic.publishers:
            for message in publisher._history or ():
                tap._offer(message)

    def wake_at_high_water(self, callback: Callable[[], object] | None) -> None:
        """Call ``callback()`` once, as soon as the queue reaches the high-water mark (or
        a publisher finds it full); ``None`` cancels. The reader sets it before it
        sleeps until its next drain."""
        self._on_high_water = callback
        if callback is not None and len(self._queue) >= self.high_water:
            self._wake_reader()

    def _wake_reader(self) -> None:
        callback = self._on_high_water
        if callback is not None:
            self._on_high_water = None
            self.high_water_wakes += 1
            callback()

    def _note_blocked(self, topic: str, now: float) -> None:
        self.blocked_publishes += 1
        if topic not in self._blocked_topics:
            self._blocked_topics.add(topic)
            log.warning(
                "%s: a publisher on '%s' waited for room at sim time %.3f s (the funnel "
                "holds %d; its reader is woken at %d): a burst larger than the room left",
                self._owner,
                topic,
                now,
                self.depth,
                self.high_water,
            )

    def statistics(self) -> FunnelStatistics:
        return FunnelStatistics(
            len(self._queue),
            self.depth,
            self.high_water,
            self.high_water_wakes,
            self.blocked_publishes,
            tuple(sorted(self._blocked_topics)),
        )

    def _took(self) -> None:
        # Room again: wake the blocked publishers in the order they blocked (FIFO).
        while self._blocked:
            self._blocked.popleft()._wake_room()

    def try_recv(self) -> Delivery | None:
        """The oldest delivery, or None when the funnel is empty (the recorder drains it
        on its own period: nothing waits on it)."""
        if not self._queue:
            return None
        delivery = Delivery(*self._queue.popleft())
        self.taps[delivery.topic].taken += 1
        if self._blocked:
            self._took()
        return delivery

    def take_all(self) -> list[tuple[str, float, Any]]:
        """Every delivery queued now, oldest first, as ``(topic, time, message)`` (one
        call per drain instead of one :meth:`try_recv` per message)."""
        queue = self._queue
        if not queue:
            return []
        taken = list(queue)
        queue.clear()
        # A tap's received minus its taken is what it has queued: none now. One update
        # per topic instead of a count per message (~10,000 a run).
        for tap in self.taps.values():
            tap.taken = tap.received
        if self._blocked:
            self._took()
        return taken
