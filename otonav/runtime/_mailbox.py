"""Typed topics, publishers and mailboxes (subscriptions), with QoS.

A message is a frozen object shared, never copied, by every subscriber. Best-effort
mailboxes keep the last ``depth`` messages and count what they drop; reliable ones
make the publisher wait for room and lose nothing. Transient-local publishers keep
their last ``depth`` messages for subscribers that join late.
"""

from __future__ import annotations

import asyncio
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Generic, NamedTuple, TypeVar

import anyio

from otonav.runtime._errors import QoSIncompatibleError, TopicTypeError
from otonav.runtime._qos import DEFAULT_QOS, Durability, QoS, Reliability, incompatibility

M = TypeVar("M")


def _type_name(tp: type[Any]) -> str:
    return f"{tp.__module__}.{tp.__qualname__}"


class MailboxStatistics(NamedTuple):
    """Counters of one mailbox (a subscription)."""

    received: int
    """Messages put into the mailbox."""
    taken: int
    """Messages the subscriber took out."""
    dropped: int
    """Messages lost to overflow (best-effort only; always 0 for reliable)."""
    queued: int
    """Messages waiting now."""
    depth: int
    """Capacity (keep-last N)."""


@dataclass(frozen=True, slots=True)
class Endpoint:
    """Who owns a port: actor name, port name (for error messages and the graph)."""

    actor: str
    port: str

    def __str__(self) -> str:
        return f"{self.actor}.{self.port}"


class Subscription(Generic[M]):
    """A mailbox: the receiving end of a topic for one subscriber."""

    __slots__ = (
        "_callback",
        "_depth",
        "_loop_waiter",
        "_queue",
        "_reliable",
        "_space_waiters",
        "dropped",
        "endpoint",
        "msg_type",
        "qos",
        "received",
        "taken",
        "topic",
    )

    def __init__(self, topic: str, msg_type: type[M], qos: QoS, endpoint: Endpoint) -> None:
        self.topic = topic
        self.msg_type = msg_type
        self.qos = qos
        self.endpoint = endpoint
        self._queue: deque[M] = deque()
        self._depth = qos.depth
        self._reliable = qos.reliability is Reliability.RELIABLE
        self._loop_waiter: asyncio.Future[None] | None = None
        self._space_waiters: deque[asyncio.Future[None]] = deque()
        self.received = 0
        self.taken = 0
        self.dropped = 0

    def _offer(self, message: M) -> bool:
        """Put ``message`` in; False when a reliable mailbox is full (caller waits)."""
        queue = self._queue
        if len(queue) >= self._depth:
            if self._reliable:
                return False
            queue.popleft()
            self.dropped += 1
        queue.append(message)
        self.received += 1
        waiter = self._loop_waiter
        if waiter is not None and not waiter.done():
            waiter.set_result(None)
        return True

    def _full(self) -> bool:
        """True when a reliable mailbox has no room (``publish_nowait`` must not block)."""
        return self._reliable and len(self._queue) >= self._depth

    def _has_room(self, n: int) -> bool:
        """True when ``n`` more messages go in now (a reliable mailbox never drops)."""
        return not self._reliable or len(self._queue) + n <= self._depth

    def has_room(self, n: int = 1) -> bool:
        """Whether ``n`` more messages go in now without a publisher waiting (always
        True for a best-effort mailbox, which drops its oldest instead). For code that
        delivers on the runtime's behalf, e.g. the replay feeder."""
        return self._has_room(n)

    def _offer_all(self, messages: Sequence[M]) -> None:
        """:meth:`_offer` each of ``messages``, in order, after :meth:`_has_room` said
        they fit: one ``extend``, and for a best-effort mailbox the oldest dropped and
        counted as one offer after another would."""
        queue = self._queue
        queue.extend(messages)
        self.received += len(messages)
        over = len(queue) - self._depth
        if over > 0:
            for _ in range(over):
                queue.popleft()
            self.dropped += over
        waiter = self._loop_waiter
        if messages and waiter is not None and not waiter.done():
            waiter.set_result(None)

    def _offer_each(self, messages: Sequence[M]) -> None:
        for message in messages:
            self._offer(message)

    def _has_room_for_one(self, n: int) -> bool:
        return n == 0 or (n == 1 and not self._full())

    def __init_subclass__(cls, **kwargs: Any) -> None:
        # A mailbox that changes how one message goes in, and not how several do, gets
        # them one by one; one that changes when it is full, and not how much room it
        # has, takes batches of one (the publisher then offers message by message).
        super().__init_subclass__(**kwargs)
        if "_offer" in vars(cls) and "_offer_all" not in vars(cls):
            cls._offer_all = Subscription._offer_each  # type: ignore[method-assign]
        if "_full" in vars(cls) and "_has_room" not in vars(cls):
            cls._has_room = Subscription._has_room_for_one  # type: ignore[method-assign]

    async def _wait_for_room(self) -> None:
        waiter = asyncio.get_running_loop().create_future()
        self._space_waiters.append(waiter)
        try:
            await waiter
        except BaseException:
            # Cancelled after being given the room: hand it to the next publisher, or
            # it would wait although there is room (a lost wakeup).
            if waiter.done() and not waiter.cancelled():
                self._wake_room()
            raise
        finally:
            if waiter in self._space_waiters:
                self._space_waiters.remove(waiter)

    def _wake_room(self) -> None:
        while self._space_waiters:
            waiter = self._space_waiters.popleft()
            if not waiter.done():
                waiter.set_result(None)
                return

    def _took_one(self) -> None:
        self.taken += 1
        if self._space_waiters:
            self._wake_room()

    def try_recv(self) -> M | None:
        """The oldest waiting message, or None when the mailbox is empty."""
        if not self._queue:
            return None
        message = self._queue.popleft()
        self._took_one()
        return message

    def take_latest(self) -> M | None:
        """The newest waiting message, discarding older ones (counted as taken), or None."""
        if not self._queue:
            return None
        message = self._queue[-1]
        for _ in range(len(self._queue)):
            self._queue.popleft()
            self._took_one()
        return message

    def drain(self) -> tuple[M, ...]:
        """Every waiting message, oldest first (all counted as taken); () when empty.
        One call where a ``try_recv`` loop costs two per message (a 20 Hz actor
        keeping a history of 100 Hz odometry)."""
        queue = self._queue
        if not queue:
            return ()
        messages = tuple(queue)
        queue.clear()
        self.taken += len(messages)
        if self._space_waiters:
            for _ in messages:
                self._wake_room()
        return messages

    async def recv(self) -> M:
        """Wait for and return the oldest message."""
        queue = self._queue
        while not queue:
            if self._loop_waiter is not None and not self._loop_waiter.done():
                raise RuntimeError(
                    f"two tasks receive from mailbox {self.endpoint} of '{self.topic}' at once; "
                    "give each task its own subscription"
                )
            self._loop_waiter = asyncio.get_running_loop().create_future()
            try:
                await self._loop_waiter
            finally:
                self._loop_waiter = None
        message = queue.popleft()
        self._took_one()
        return message

    def __aiter__(self) -> Subscription[M]:
        return self

    async def __anext__(self) -> M:
        return await self.recv()

    def deliver_to(self, callback: Callable[[M], object]) -> None:
        """From now on hand each message to ``callback(message)`` inside the publisher's
        call, as a ROS 2 subscription callback but with no task of its own: the waiting
        messages first, then each as it is published (counted received and taken; never
        full). What ``callback`` raises, the publisher raises. For an actor's input that
        needs no wake-up of its own: the bridge applies /wheel_cmd so (ADR 0084)."""
        self._callback = callback
        self.__class__ = _CallbackSubscription
        while (message := self.try_recv()) is not None:
            callback(message)

    def statistics(self) -> MailboxStatistics:
        return MailboxStatistics(
            self.received, self.taken, self.dropped, len(self._queue), self._depth
        )


class _CallbackSubscription(Subscription[M]):
    """A mailbox whose messages go to its callback as they are offered
    (:meth:`Subscription.deliver_to`)."""

    __slots__ = ()
    _callback: Callable[[M], object]

    def _offer(self, message: M) -> bool:
        self.received += 1
        self.taken += 1
        self._callback(message)
        return True

    def _has_room(self, n: int) -> bool:
        return True


class Publisher(Generic[M]):
    """The sending end of a topic for one publisher."""

    __slots__ = (
        "_accepted",
        "_history",
        "_topic",
        "endpoint",
        "msg_type",
        "published",
        "qos",
        "topic",
    )

    def __init__(
        self,
        topic: Topic[M],
        qos: QoS,
        endpoint: Endpoint,
    ) -> None:
        self.topic = topic.name
        self.msg_type = topic.msg_type
        self.qos = qos
        self.endpoint = endpoint
        # Read the topic's subscriber list at each publish: a late joiner is seen at once.
        self._topic = topic
        self._history: deque[M] | None = (
            deque(maxlen=qos.depth) if qos.durability is Durability.TRANSIENT_LOCAL else None
        )
        self.published = 0
        self._accepted: type[Any] = self.msg_type
        """Another class whose messages this publisher takes as ``msg_type`` ones."""

    def get_subscription_count(self) -> int:
        """How many mailboxes the topic has now (rclpy's ``get_subscription_count``): a
        publisher may skip building a message no one would receive. A late joiner is
        counted at once; a latched publisher keeps history, so it should not skip."""
        return len(self._topic.subscriptions)

    def _check_type(self, message: object) -> None:
        # A class that stands for the topic's type (a flat message, otonav.msgs._flat,
        # built on first use): accepted as it is, and from now on without this call.
        if getattr(type(message), "stands_for", None) is self.msg_type:
            self._accepted = type(message)
            return
        # What the object says it is: a replayed input decoded on first use becomes its
        # message class when asked (otonav.replay._lazy), e.g. by an actor relaying it.
        if message.__class__ is self.msg_type:
            return
        if type(message) is not self.msg_type:
            raise TopicTypeError(
                f"{self.endpoint} published a {_type_name(type(message))} on '{self.topic}', "
                f"whose type is {_type_name(self.msg_type)}; publish a "
                f"{self.msg_type.__qualname__} or wire the port to a topic of that type"
            )

    async def publish(self, message: M) -> None:
        """Deliver ``message`` to every subscriber; waits only while a reliable
        subscriber's mailbox is full (backpressure)."""
        if type(message) is not self.msg_type and type(message) is not self._accepted:
            self._check_type(message)
        self.published += 1
        if self._history is not None:
            self._history.append(message)
        # Bus.unsubscribe replaces the list rather than mutate it, so this loop is safe
        # while it waits for room, with no copy per message.
        for subscription in self._topic.subscriptions:
            while not subscription._offer(message):
                await subscription._wait_for_room()

    def try_publish_all(self, messages: Sequence[M]) -> bool:
        """Deliver all of ``messages`` now, in order, as one :meth:`publish_nowait` after
        another would, and return True; when a reliable mailbox has no room for all of
        them, deliver none and return False (then publish them one by one). For a
        publisher with a batch per wake (the CAN tap: ~15 frames per flush): one
        ``extend`` per mailbox instead of a call per message and mailbox."""
        msg_type, accepted = self.msg_type, self._accepted
        for message in messages:
            if type(message) is not msg_type and type(message) is not accepted:
                self._check_type(message)
                accepted = self._accepted
        n = len(messages)
        subscriptions = self._topic.subscriptions
        for subscription in subscriptions:
            if not subscription._has_room(n):
                return False
        self.published += n
        if self._history is not None:
            self._history.extend(messages)
        for subscription in subscriptions:
            subscription._offer_all(messages)
        return True

    def publish_nowait(self, message: M) -> None:
        """Like :meth:`publish` for callers that cannot wait: raises ``anyio.WouldBlock``
        rather than wait when a reliable mailbox is full (no subscriber receives it).
        The one non-waiting publish (ADR 0056), as ``send_nowait``/``put_nowait`` are in
        anyio and asyncio. For a publisher that sends several messages per wake it is
        also the fast path: no coroutine per message (0.3-0.4 us each, ADR 0033);
        ``except anyio.WouldBlock: await publish(message)`` when it must not drop."""
        if type(message) is not self.msg_type and type(message) is not self._accepted:
            self._check_type(message)
        for subscription in self._topic.subscriptions:
            if subscription._full():
                raise anyio.WouldBlock(f"mailbox {subscription.endpoint} of '{self.topic}' is full")
        self.published += 1
        if self._history is not None:
            self._history.append(message)
        for subscription in self._topic.subscriptions:
            subscription._offer(message)


class Topic(Generic[M]):
    """A named, typed channel: its publishers and subscriptions, in wiring order."""

    __slots__ = ("msg_type", "name", "publishers", "subscriptions")

    def __init__(self, name: str, msg_type: type[M]) -> None:
        self.name = name
        self.msg_type = msg_type
        self.publishers: list[Publisher[M]] = []
        self.subscriptions: list[Subscription[M]] = []

    def add_subscription(self, subscription: Subscription[M]) -> None:
        """Join the topic. The list is replaced, never changed in place: a publisher
        blocked mid-delivery keeps iterating the list it started with, so a joiner
        that already got the message from transient-local history is not offered it a
        second time when that publisher resumes."""
        self.subscriptions = [*self.subscriptions, subscription]


class Bus:
    """All topics of a system. Wiring checks types and QoS here, once."""

    def __init__(self) -> None:
        self.topics: dict[str, Topic[Any]] = {}
        self._topic_listeners: list[Callable[[Topic[Any]], None]] = []

    def add_topic_listener(self, listener: Callable[[Topic[Any]], None]) -> None:
        """Call ``listener(topic)`` for every topic created from now on (a recorder
        subscribing to everything, like ``ros2 bag record -a`` discovering topics)."""
        self._topic_listeners.append(listener)

    def _topic(self, name: str, msg_type: type[M], endpoint: Endpoint) -> Topic[M]:
        if not name.startswith("/"):
            raise ValueError(f"{endpoint}: topic name '{name}' must be absolute, e.g. '/{name}'")
        topic = self.topics.get(name)
        if topic is None:
            topic = Topic(name, msg_type)
            self.topics[name] = topic
            for listener in self._topic_listeners:
                listener(topic)
            return topic
        if topic.msg_type is not msg_type:
            ends = [str(p.endpoint) for p in topic.publishers] + [
                str(s.endpoint) for s in topic.subscriptions
            ]
            raise TopicTypeError(
                f"{endpoint} wants topic '{name}' as {_type_name(msg_type)}, but "
                f"{', '.join(ends) or 'an earlier port'} already use it as "
                f"{_type_name(topic.msg_type)}; use one message type per topic "
                "(rename one of the topics or change the port's type)"
            )
        return topic

    def publisher(
        self, name: str, msg_type: type[M], qos: QoS = DEFAULT_QOS, *, endpoint: Endpoint
    ) -> Publisher[M]:
        """Add a publisher; raises if its type or QoS cannot serve existing subscribers."""
        topic = self._topic(name, msg_type, endpoint)
        for subscription in topic.subscriptions:
            _check_pair(name, qos, endpoint, subscription.qos, subscription.endpoint)
        publisher = Publisher(topic, qos, endpoint)
        topic.publishers.append(publisher)
        return publisher

    def unsubscribe(self, subscription: Subscription[Any]) -> None:
        """Remove a mailbox from its topic; publishers waiting on it for room are freed.
        Idempotent."""
        topic = self.topics.get(subscription.topic)
        if topic is not None and subscription in topic.subscriptions:
            # A new list: a publisher iterating the old one mid-delivery is unaffected.
            topic.subscriptions = [s for s in topic.subscriptions if s is not subscription]
        while subscription._space_waiters:
            waiter = subscription._space_waiters.popleft()
            if not waiter.done():
                waiter.set_result(None)
        subscription._depth = 1 << 62  # a publisher mid-delivery finds room and moves on

    def subscribe(
        self, name: str, msg_type: type[M], qos: QoS = DEFAULT_QOS, *, endpoint: Endpoint
    ) -> Subscription[M]:
        """Add a mailbox; raises if its type or QoS cannot be served by existing
        publishers. A transient-local mailbox gets the publishers' kept history."""
        topic = self._topic(name, msg_type, endpoint)
        for publisher in topic.publishers:
            _check_pair(name, publisher.qos, publisher.endpoint, qos, endpoint)
        subscription = Subscription(name, msg_type, qos, endpoint)
        if qos.durability is Durability.TRANSIENT_LOCAL:
            kept = [m for p in topic.publishers for m in (p._history or ())]
            for message in kept[-qos.depth :]:
                subscription._offer(message)
        topic.add_subscription(subscription)
        return subscription


def _check_pair(
    topic: str, offered: QoS, publisher: Endpoint, requested: QoS, subscriber: Endpoint
) -> None:
    reason = incompatibility(offered, requested)
    if reason is not None:
        raise QoSIncompatibleError(
            f"QoS mismatch on '{topic}': publisher {publisher} ({offered}) cannot serve "
            f"subscriber {subscriber} ({requested}): {reason}. ROS 2 would leave this pair "
            "silently unconnected; otonav refuses to wire it."
        )
