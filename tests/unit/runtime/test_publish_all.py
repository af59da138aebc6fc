"""``Publisher.try_publish_all``: a batch goes into every mailbox (and a recorder's funnel)
exactly as one ``publish_nowait`` after another would put it, or, when a reliable mailbox
has no room for all of it, nowhere."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import anyio
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from otonav.runtime import QoS, Reliability, TopicTypeError, virtual_loop_factory
from otonav.runtime._funnel import Funnel
from otonav.runtime._mailbox import Bus, Endpoint, Publisher, Subscription
from otonav.runtime._qos import Durability

pytestmark = pytest.mark.unit


@dataclass(frozen=True, slots=True)
class Ping:
    n: int


@dataclass(frozen=True)
class Case:
    mailboxes: tuple[tuple[bool, int, int], ...]
    """(reliable, depth, messages already queued) per mailbox"""
    funnel: tuple[int, int, int] | None
    """(depth, high water, deliveries already queued) of a recorder's funnel"""
    latched: bool
    blocked: bool
    """the funnel's tap remembers a publisher that gave up waiting for room"""
    batch: int


@st.composite
def cases(draw: st.DrawFn) -> Case:
    mailboxes = []
    for _ in range(draw(st.integers(0, 3))):
        depth = draw(st.integers(1, 6))
        mailboxes.append((draw(st.booleans()), depth, draw(st.integers(0, depth))))
    funnel = None
    if draw(st.booleans()):
        depth = draw(st.integers(1, 12))
        funnel = (depth, draw(st.integers(1, depth)), draw(st.integers(0, depth)))
    return Case(
        tuple(mailboxes),
        funnel,
        draw(st.booleans()),
        funnel is not None and draw(st.booleans()),
        draw(st.integers(0, 8)),
    )


class World:
    """One publisher, its mailboxes and a funnel, filled as ``case`` says."""

    def __init__(self, case: Case) -> None:
        self.bus = Bus()
        self.now = 0.5
        self.woken = 0
        durability = Durability.TRANSIENT_LOCAL if case.latched else Durability.VOLATILE
        self.pub: Publisher[Ping] = self.bus.publisher(
            "/t", Ping, QoS(depth=3, durability=durability), endpoint=Endpoint("p", "out")
        )
        self.subs: list[Subscription[Ping]] = []
        for i, (reliable, depth, queued) in enumerate(case.mailboxes):
            qos = QoS(Reliability.RELIABLE if reliable else Reliability.BEST_EFFORT, depth=depth)
            sub = self.bus.subscribe("/t", Ping, qos, endpoint=Endpoint(f"s{i}", "in"))
            for k in range(queued):
                sub._offer(Ping(-1 - k))
            self.subs.append(sub)
        self.funnel: Funnel | None = None
        if case.funnel is not None:
            depth, high_water, queued = case.funnel
            self.funnel = Funnel(
                self.bus, "rec", lambda: self.now, depth=depth, high_water=high_water
            )
            other = self.bus.publisher("/other", Ping, endpoint=Endpoint("o", "out"))
            for k in range(queued):
                other.publish_nowait(Ping(-100 - k))
            self.funnel.wake_at_high_water(self.wake)
            if case.blocked:
                self.funnel.taps["/t"]._blocked_at = 0.25
        self.now = 1.5

    def wake(self) -> None:
        self.woken += 1

    def state(self) -> tuple[Any, ...]:
        funnel = self.funnel
        return (
            self.pub.published,
            list(self.pub._history or ()),
            [(list(s._queue), s.statistics()) for s in self.subs],
            None
            if funnel is None
            else (
                list(funnel._queue),
                funnel.statistics(),
                funnel.taps["/t"].statistics(),
                funnel.taps["/t"]._blocked_at,
            ),
            self.woken,
        )


@settings(max_examples=300, deadline=None)
@given(cases())
def test_a_batch_goes_in_as_one_message_after_another_or_not_at_all(case: Case) -> None:
    batch = [Ping(i) for i in range(case.batch)]
    one_by_one, at_once = World(case), World(case)
    before = at_once.state()
    delivered = 0
    for message in batch:
        try:
            one_by_one.pub.publish_nowait(message)
        except anyio.WouldBlock:
            break
        delivered += 1
    if at_once.pub.try_publish_all(batch):
        assert delivered == len(batch)
        assert at_once.state() == one_by_one.state()
    else:
        assert delivered < len(batch)  # only when one by one would have stopped too
        assert at_once.state() == before


def test_the_funnel_stamps_a_batch_with_its_instant_and_wakes_the_reader_once() -> None:
    case = Case(mailboxes=(), funnel=(10, 3, 1), latched=False, blocked=True, batch=5)
    world = World(case)
    assert world.pub.try_publish_all([Ping(i) for i in range(5)])
    assert world.funnel is not None
    assert [(t, when, m.n) for t, when, m in world.funnel._queue] == [
        ("/other", 0.5, -100),
        ("/t", 0.25, 0),  # the instant a publisher that gave up waiting had published
        *(("/t", 1.5, i) for i in range(1, 5)),
    ]
    assert world.woken == 1
    assert world.funnel.statistics().high_water_wakes == 1


def test_a_waiting_reader_is_woken_by_a_batch() -> None:
    bus = Bus()
    pub = bus.publisher("/t", Ping, endpoint=Endpoint("p", "out"))
    sub = bus.subscribe("/t", Ping, QoS(depth=8), endpoint=Endpoint("s", "in"))

    async def main() -> list[int]:
        got: list[int] = []

        async def reader() -> None:
            got.append((await sub.recv()).n)

        async with anyio.create_task_group() as tg:
            tg.start_soon(reader)
            await anyio.sleep(0.1)
            assert pub.try_publish_all([Ping(1), Ping(2)])
        return got + [m.n for m in sub.drain()]

    got = anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})
    assert got == [1, 2]


class _Counting(Subscription[Ping]):
    """A mailbox that changes how one message goes in (as a live view's tap does)."""

    __slots__ = ("seen",)

    def __init__(self, *args: Any) -> None:
        super().__init__(*args)
        self.seen: list[int] = []

    def _offer(self, message: Ping) -> bool:
        self.seen.append(message.n)
        return super()._offer(message)


class _NeverFull(_Counting):
    """And one that also says when it is full, but not how much room it has."""

    __slots__ = ()

    def _full(self) -> bool:
        return False


def test_a_mailbox_that_offers_its_own_way_gets_a_batch_one_by_one() -> None:
    bus = Bus()
    pub = bus.publisher("/t", Ping, endpoint=Endpoint("p", "out"))
    topic = bus.topics["/t"]
    counting = _Counting("/t", Ping, QoS(depth=4), Endpoint("c", "in"))
    topic.add_subscription(counting)
    assert pub.try_publish_all([Ping(1), Ping(2), Ping(3)])
    assert counting.seen == [1, 2, 3]
    assert not pub.try_publish_all([Ping(4), Ping(5)])  # no room for two: none goes in
    assert counting.seen == [1, 2, 3]
    never_full = _NeverFull("/t", Ping, QoS(depth=4), Endpoint("n", "in"))
    topic.add_subscription(never_full)
    # It cannot say whether two fit: a batch of two is refused, one by one goes through.
    assert not pub.try_publish_all([Ping(4), Ping(5)])
    assert pub.try_publish_all([Ping(4)])
    assert never_full.seen == [4]


def test_a_batch_with_a_message_of_another_type_is_refused_whole() -> None:
    bus = Bus()
    pub = bus.publisher("/t", Ping, endpoint=Endpoint("p", "out"))
    sub = bus.subscribe("/t", Ping, QoS(depth=8), endpoint=Endpoint("s", "in"))
    wrong: Sequence[Any] = [Ping(1), "not a ping"]
    with pytest.raises(TopicTypeError):
        pub.try_publish_all(wrong)
    assert sub.statistics().received == 0
    assert pub.published == 0
