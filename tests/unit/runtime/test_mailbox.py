"""Typed topics and QoS: wiring errors, exact drop counts, backpressure, late joiners."""

from __future__ import annotations

import asyncio
from dataclasses import dataclass

import anyio
import pytest

from otonav.runtime import (
    LATCHED_QOS,
    SENSOR_DATA_QOS,
    Actor,
    Bus,
    Durability,
    Endpoint,
    Input,
    Output,
    QoS,
    QoSIncompatibleError,
    Reliability,
    System,
    TopicTypeError,
    virtual_loop_factory,
)

pytestmark = pytest.mark.unit


@dataclass(frozen=True, slots=True)
class Ping:
    n: int


@dataclass(frozen=True, slots=True)
class Pong:
    n: int


def _run(main: object) -> None:
    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})  # type: ignore[arg-type]


BEST_EFFORT = QoS(Reliability.BEST_EFFORT)
VOLATILE_RELIABLE = QoS(Reliability.RELIABLE)
TRANSIENT = QoS(durability=Durability.TRANSIENT_LOCAL)


@pytest.mark.parametrize(
    ("offered", "requested", "fragment"),
    [
        (BEST_EFFORT, VOLATILE_RELIABLE, "requests reliable delivery"),
        (VOLATILE_RELIABLE, TRANSIENT, "requests transient_local durability"),
        (BEST_EFFORT, TRANSIENT, "requests reliable delivery"),
    ],
)
@pytest.mark.parametrize("publisher_first", [True, False])
def test_incompatible_qos_fails_at_wiring_naming_both_ends_and_the_fix(
    offered: QoS, requested: QoS, fragment: str, publisher_first: bool
) -> None:
    bus = Bus()
    pub_end, sub_end = Endpoint("lidar", "scan"), Endpoint("nav", "scan_in")

    def wire() -> None:
        if publisher_first:
            bus.publisher("/scan", Ping, offered, endpoint=pub_end)
            bus.subscribe("/scan", Ping, requested, endpoint=sub_end)
        else:
            bus.subscribe("/scan", Ping, requested, endpoint=sub_end)
            bus.publisher("/scan", Ping, offered, endpoint=pub_end)

    with pytest.raises(QoSIncompatibleError) as err:
        wire()
    text = str(err.value)
    assert "'/scan'" in text
    assert "lidar.scan" in text
    assert "nav.scan_in" in text
    assert fragment in text
    assert "fix:" in text


@pytest.mark.parametrize(
    ("offered", "requested"),
    [
        (VOLATILE_RELIABLE, BEST_EFFORT),
        (BEST_EFFORT, BEST_EFFORT),
        (TRANSIENT, VOLATILE_RELIABLE),
        (TRANSIENT, TRANSIENT),
        (LATCHED_QOS, SENSOR_DATA_QOS),
    ],
)
def test_compatible_qos_pairs_wire(offered: QoS, requested: QoS) -> None:
    bus = Bus()
    bus.publisher("/t", Ping, offered, endpoint=Endpoint("a", "out"))
    bus.subscribe("/t", Ping, requested, endpoint=Endpoint("b", "in"))


def test_two_port_types_on_one_topic_name_actor_port_topic_and_both_types() -> None:
    class Talker(Actor):
        out = Output("/chatter", Ping)

    class Listener(Actor):
        inp = Input("/chatter", Pong)

    with pytest.raises(TopicTypeError) as err:
        System([Talker(), Listener()])
    text = str(err.value)
    assert "listener.inp" in text
    assert "'/chatter'" in text
    assert "Pong" in text
    assert "Ping" in text
    assert "talker.out" in text


def test_publishing_the_wrong_type_names_port_topic_and_types() -> None:
    bus = Bus()
    pub = bus.publisher("/chatter", Ping, endpoint=Endpoint("talker", "out"))

    async def main() -> None:
        with pytest.raises(TopicTypeError) as err:
            await pub.publish(Pong(1))  # type: ignore[arg-type]
        assert "talker.out" in str(err.value)
        assert "Pong" in str(err.value)
        assert "'/chatter'" in str(err.value)
        assert "Ping" in str(err.value)

    _run(main)


def test_best_effort_drops_oldest_and_counts_exactly() -> None:
    bus = Bus()
    pub = bus.publisher("/scan", Ping, BEST_EFFORT, endpoint=Endpoint("a", "o"))
    sub = bus.subscribe(
        "/scan", Ping, QoS(Reliability.BEST_EFFORT, depth=3), endpoint=Endpoint("b", "i")
    )

    async def main() -> None:
        for n in range(10):
            await pub.publish(Ping(n))
        got = [sub.try_recv() for _ in range(4)]
        assert got == [Ping(7), Ping(8), Ping(9), None]
        stats = sub.statistics()
        assert (stats.received, stats.taken, stats.dropped, stats.queued) == (10, 3, 7, 0)

    _run(main)


def test_drain_empties_the_mailbox_oldest_first_and_counts_each() -> None:
    bus = Bus()
    pub = bus.publisher("/odom", Ping, BEST_EFFORT, endpoint=Endpoint("a", "o"))
    sub = bus.subscribe(
        "/odom", Ping, QoS(Reliability.BEST_EFFORT, depth=3), endpoint=Endpoint("b", "i")
    )

    async def main() -> None:
        assert sub.drain() == ()
        for n in range(5):
            await pub.publish(Ping(n))
        assert sub.drain() == (Ping(2), Ping(3), Ping(4))
        assert sub.drain() == ()
        stats = sub.statistics()
        assert (stats.received, stats.taken, stats.dropped, stats.queued) == (5, 3, 2, 0)

    _run(main)


def test_drain_lets_a_blocked_reliable_publisher_go_on() -> None:
    sent: list[int] = []

    class Burst(Actor):
        out = Output("/data", Ping)

        async def run(self) -> None:
            for n in range(6):
                await self.out.publish(Ping(n))
                sent.append(n)

    class Batch(Actor):
        inp = Input("/data", Ping, QoS(depth=2))

        def __init__(self) -> None:
            super().__init__("batch")
            self.got: list[tuple[Ping, ...]] = []

        async def run(self) -> None:
            while sum(len(b) for b in self.got) < 6:
                await self.clock.sleep(1.0)
                self.got.append(self.inp.drain())

    batch = Batch()

    async def main() -> None:
        await System([Burst(), batch]).run()

    _run(main)
    assert [p.n for b in batch.got for p in b] == list(range(6))
    assert sent == list(range(6))


def test_one_message_object_is_shared_by_all_subscribers() -> None:
    bus = Bus()
    pub = bus.publisher("/t", Ping, endpoint=Endpoint("a", "o"))
    subs = [bus.subscribe("/t", Ping, endpoint=Endpoint(f"s{i}", "i")) for i in range(3)]

    async def main() -> None:
        message = Ping(1)
        await pub.publish(message)
        assert all(s.try_recv() is message for s in subs)

    _run(main)


def test_reliable_slow_consumer_loses_nothing_and_publisher_waits() -> None:
    received: list[int] = []
    publish_times: list[float] = []

    class Fast(Actor):
        out = Output("/data", Ping)

        async def run(self) -> None:
            for n in range(100):
                await self.out.publish(Ping(n))
                publish_times.append(self.clock.now())

    class Slow(Actor):
        inp = Input("/data", Ping, QoS(depth=4))

        async def run(self) -> None:
            while len(received) < 100:
                received.append((await self.inp.recv()).n)
                await self.clock.sleep(0.1)

    async def main() -> None:
        system = System([Fast(), Slow()])
        await system.run()
        stats = system.graph().topic("/data").subscriptions[0].statistics
        assert stats.dropped == 0
        assert stats.received == 100

    _run(main)
    assert received == list(range(100))
    # Backpressure: the publisher was held back by the consumer's pace. The consumer
    # takes message k at 0.1*k s, freeing room for message k+4; so message 99 goes out
    # when message 95 is taken, at 9.5 s (0..4 go out at 0 s: 4 queued + 1 taken).
    assert publish_times[:5] == [0.0] * 5
    assert publish_times[-1] == pytest.approx(9.5, abs=1e-6)


def test_transient_local_late_joiner_gets_the_last_n() -> None:
    bus = Bus()
    pub = bus.publisher(
        "/goal",
        Ping,
        QoS(depth=3, durability=Durability.TRANSIENT_LOCAL),
        endpoint=Endpoint("a", "o"),
    )

    async def main() -> None:
        for n in range(5):
            await pub.publish(Ping(n))
        late = bus.subscribe("/goal", Ping, TRANSIENT, endpoint=Endpoint("late", "i"))
        volatile = bus.subscribe("/goal", Ping, VOLATILE_RELIABLE, endpoint=Endpoint("vol", "i"))
        assert [late.try_recv() for _ in range(4)] == [Ping(2), Ping(3), Ping(4), None]
        assert volatile.try_recv() is None

    _run(main)


def test_take_latest_discards_older_messages() -> None:
    bus = Bus()
    pub = bus.publisher("/odom", Ping, endpoint=Endpoint("a", "o"))
    sub = bus.subscribe("/odom", Ping, endpoint=Endpoint("b", "i"))

    async def main() -> None:
        for n in range(4):
            await pub.publish(Ping(n))
        assert sub.take_latest() == Ping(3)
        assert sub.take_latest() is None
        assert sub.statistics().taken == 4

    _run(main)


def test_unsubscribe_mid_backpressure_frees_the_publisher_and_skips_no_one() -> None:
    bus = Bus()
    pub = bus.publisher("/t", Ping, endpoint=Endpoint("a", "o"))
    stuck = bus.subscribe("/t", Ping, QoS(depth=1), endpoint=Endpoint("stuck", "i"))
    after = bus.subscribe("/t", Ping, QoS(depth=10), endpoint=Endpoint("after", "i"))

    async def main() -> None:
        await pub.publish(Ping(0))
        async with anyio.create_task_group() as tg:
            tg.start_soon(pub.publish, Ping(1))  # blocks: 'stuck' is full
            await anyio.sleep(0.1)
            assert after.statistics().received == 1  # Ping(1) not delivered past 'stuck' yet
            bus.unsubscribe(stuck)
        # The publisher moved on and delivered to the next subscriber.
        assert [after.try_recv(), after.try_recv()] == [Ping(0), Ping(1)]
        assert bus.topics["/t"].subscriptions == [after]

    _run(main)


def test_a_publisher_cancelled_after_being_given_room_hands_it_on() -> None:
    bus = Bus()
    pub = bus.publisher("/t", Ping, endpoint=Endpoint("a", "o"))
    sub = bus.subscribe("/t", Ping, QoS(depth=1), endpoint=Endpoint("b", "i"))

    async def main() -> None:
        await pub.publish(Ping(0))  # the mailbox is full
        first = asyncio.ensure_future(pub.publish(Ping(1)))
        second = asyncio.ensure_future(pub.publish(Ping(2)))
        await anyio.sleep(0.1)  # both wait for room
        assert sub.try_recv() == Ping(0)  # room for one: the first is woken...
        first.cancel()  # ...but cancelled before it runs
        await anyio.sleep(0.1)
        assert second.done()  # the room went to the second publisher
        assert sub.try_recv() == Ping(2)

    _run(main)


@pytest.mark.parametrize("late", ["subscription", "funnel tap"])
def test_a_late_transient_local_joiner_mid_delivery_gets_the_message_once(late: str) -> None:
    """A publisher blocked mid-delivery (a full reliable mailbox) has already kept the
    message in its history; a transient-local subscriber (or a recorder's tap) joining
    now gets it from the history and must not get it again when the publisher resumes.
    (It did: the joiner was appended to the very list the publisher was iterating.)"""
    from otonav.runtime._funnel import Funnel

    bus = Bus()
    kept = QoS(depth=5, durability=Durability.TRANSIENT_LOCAL)
    pub = bus.publisher("/goal", Ping, kept, endpoint=Endpoint("a", "o"))
    stuck = bus.subscribe("/goal", Ping, QoS(depth=1), endpoint=Endpoint("stuck", "i"))

    async def main() -> None:
        await pub.publish(Ping(0))  # 'stuck' is full now
        async with anyio.create_task_group() as tg:
            tg.start_soon(pub.publish, Ping(1))  # kept in history, then blocks on 'stuck'
            await anyio.sleep(0.1)
            if late == "subscription":
                joiner = bus.subscribe("/goal", Ping, kept, endpoint=Endpoint("late", "i"))
            else:
                funnel = Funnel(Bus(), "recorder", lambda: 0.0)
                funnel._tap(bus.topics["/goal"])
            assert stuck.try_recv() == Ping(0)  # room: the publisher resumes
        if late == "subscription":
            got = []
            while (message := joiner.try_recv()) is not None:
                got.append(message)
        else:
            got = []
            while (delivery := funnel.try_recv()) is not None:
                got.append(delivery.message)
        assert got == [Ping(0), Ping(1)]

    _run(main)


def test_publish_nowait_delivers_to_all_or_to_none() -> None:
    bus = Bus()
    pub = bus.publisher("/data", Ping, endpoint=Endpoint("p", "out"))
    loose = bus.subscribe(
        "/data", Ping, QoS(Reliability.BEST_EFFORT, depth=1), endpoint=Endpoint("a", "in")
    )
    strict = bus.subscribe("/data", Ping, QoS(depth=2), endpoint=Endpoint("b", "in"))
    pub.publish_nowait(Ping(0))
    pub.publish_nowait(Ping(1))
    # The reliable mailbox is full: nothing is delivered, to anyone, and nothing counted.
    with pytest.raises(anyio.WouldBlock, match=r"b\.in"):
        pub.publish_nowait(Ping(2))
    assert pub.published == 2
    assert [m.n for m in loose.drain()] == [1]  # best effort kept the newest
    assert [m.n for m in strict.drain()] == [0, 1]
    pub.publish_nowait(Ping(3))
    assert [m.n for m in strict.drain()] == [3]
    with pytest.raises(TopicTypeError):
        pub.publish_nowait("not a ping")  # type: ignore[arg-type]


def test_a_mailbox_delivering_to_a_callback_hands_over_in_the_publishers_call() -> None:
    """deliver_to (ADR 0084): the waiting messages first, in order, then each one inside
    publish/publish_nowait/try_publish_all, counted received and taken, never full;
    what the callback raises, the publisher raises."""
    bus = Bus()
    pub = bus.publisher("/p", Ping, VOLATILE_RELIABLE, endpoint=Endpoint("a", "out"))
    sub = bus.subscribe("/p", Ping, QoS(depth=2), endpoint=Endpoint("b", "in"))
    got: list[int] = []
    pub.publish_nowait(Ping(1))
    pub.publish_nowait(Ping(2))
    sub.deliver_to(lambda m: got.append(m.n))
    assert got == [1, 2]
    for n in (3, 4, 5):
        pub.publish_nowait(Ping(n))  # depth 2, reliable: it would be full without it
    assert pub.try_publish_all([Ping(6), Ping(7), Ping(8)])
    assert got == [1, 2, 3, 4, 5, 6, 7, 8]
    stats = sub.statistics()
    assert (stats.received, stats.taken, stats.queued, stats.dropped) == (8, 8, 0, 0)

    def refuse(m: Ping) -> None:
        raise ValueError(f"bad {m.n}")

    sub.deliver_to(refuse)
    with pytest.raises(ValueError, match="bad 9"):
        pub.publish_nowait(Ping(9))
