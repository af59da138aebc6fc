"""A funnel: one mailbox fed by many topics, keeping the global publish order.

A recorder wants every message of every topic in the order it was published, stamped
with the instant it was published. Each topic gets an ordinary-looking subscription (it
shows in the graph with its counters) whose deliveries go into the funnel's one queue.
Reliable: when the funnel is full, publishers wait (backpressure); nothing is lost.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from typing import Any, NamedTuple

from otonav.runtime.mailbox import Bus, Endpoint, Subscription, Topic
from otonav.runtime.qos import QoS, Reliability


class Delivery(NamedTuple):
    topic: str
    time: float
    message: Any


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
        if len(funnel._queue) >= funnel.depth:
            # Full: the publisher waits. Remember when it published, so the message is
            # stamped with that instant, not with the instant room was found.
            if self._blocked_at is None:
                self._blocked_at = funnel._now()
            funnel._blocked.append(self)  # one entry per waiting publisher
            return False
        stamp, self._blocked_at = self._blocked_at, None
        funnel._queue.append(
            Delivery(self.topic, funnel._now() if stamp is None else stamp, message)
        )
        self.received += 1
        return True

    def _full(self) -> bool:
        return len(self._funnel._queue) >= self._funnel.depth


class Funnel:
    """Taps topics of ``bus`` (all, or those ``wanted`` accepts), now and as they appear."""

    def __init__(
        self,
        bus: Bus,
        owner: str,
        now: Callable[[], float],
        *,
        wanted: Callable[[str], bool] = lambda _name: True,
        depth: int = 10_000,
    ) -> None:
        self.depth = depth
        self._owner = owner
        self._now = now
        self._wanted = wanted
        self._queue: deque[Delivery] = deque()
        self._blocked: deque[_Tap] = deque()
        self.taps: dict[str, _Tap] = {}
        for topic in list(bus.topics.values()):
            self._tap(topic)
        bus.add_topic_listener(self._tap)

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

    def _took(self) -> None:
        # Room again: wake the blocked publishers in the order they blocked (FIFO).
        while self._blocked:
            self._blocked.popleft()._wake_room()

    def try_recv(self) -> Delivery | None:
        """The oldest delivery, or None when the funnel is empty (the recorder drains it
        on its own period: nothing waits on it)."""
        if not self._queue:
            return None
        delivery = self._queue.popleft()
        self.taps[delivery.topic].taken += 1
        if self._blocked:
            self._took()
        return delivery
