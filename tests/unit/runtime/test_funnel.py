"""The funnel: many topics into one queue, in publish order, stamped at publication,
with backpressure that loses nothing and wakes publishers first come, first served."""

from __future__ import annotations

from dataclasses import dataclass

import anyio
import anyio.lowlevel
import pytest

from otonav.runtime import SENSOR_DATA_QOS, Bus, virtual_loop_factory
from otonav.runtime._funnel import Funnel
from otonav.runtime._mailbox import Endpoint

pytestmark = pytest.mark.unit


@dataclass(frozen=True, slots=True)
class Msg:
    n: int


def test_publish_order_stamps_and_late_topics() -> None:
    bus = Bus()
    a = bus.publisher("/a", Msg, endpoint=Endpoint("x", "a"))

    async def main() -> list[tuple[str, float, int]]:
        funnel = Funnel(bus, "rec", anyio.current_time)
        await a.publish(Msg(1))
        await anyio.sleep(0.5)
        late = bus.publisher("/z_late", Msg, SENSOR_DATA_QOS, endpoint=Endpoint("y", "z"))
        await late.publish(Msg(2))
        await a.publish(Msg(3))
        got = []
        while (d := funnel.try_recv()) is not None:
            got.append((d.topic, d.time, d.message.n))
        return got

    got = anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})
    assert got == [("/a", 0.0, 1), ("/z_late", 0.5, 2), ("/a", 0.5, 3)]


def test_backpressure_keeps_publication_stamps_and_first_come_first_served() -> None:
    bus = Bus()
    pubs = {t: bus.publisher(t, Msg, endpoint=Endpoint("x", t)) for t in ("/b", "/a")}

    async def main() -> list[tuple[str, float, int]]:
        funnel = Funnel(bus, "rec", anyio.current_time, depth=1)
        got: list[tuple[str, float, int]] = []
        async with anyio.create_task_group() as tg:
            await pubs["/b"].publish(Msg(0))  # fills the funnel
            tg.start_soon(pubs["/b"].publish, Msg(1))  # blocks at t=0
            await anyio.sleep(0.2)
            tg.start_soon(pubs["/a"].publish, Msg(2))  # blocks at t=0.2
            await anyio.sleep(0.2)
            for _ in range(3):
                d = funnel.try_recv()
                assert d is not None
                got.append((d.topic, d.time, d.message.n))
                await anyio.lowlevel.checkpoint()
                await anyio.lowlevel.checkpoint()
        return got

    got = anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})
    # /b blocked first, so it goes first, although /a sorts first by name; each keeps
    # the instant it was published at, not the instant room was found.
    assert got == [("/b", 0.0, 0), ("/b", 0.0, 1), ("/a", 0.2, 2)]


def test_take_all_is_every_try_recv_at_once_and_counts_what_was_taken() -> None:
    bus = Bus()
    pubs = {t: bus.publisher(t, Msg, endpoint=Endpoint("x", t)) for t in ("/b", "/a")}

    async def main() -> tuple[list[tuple[str, float, int]], dict[str, int], int]:
        funnel = Funnel(bus, "rec", anyio.current_time, depth=3)
        got: list[tuple[str, float, int]] = []
        async with anyio.create_task_group() as tg:
            for n in range(3):
                await pubs["/b" if n % 2 else "/a"].publish(Msg(n))
                await anyio.sleep(0.1)
            tg.start_soon(pubs["/a"].publish, Msg(3))  # the funnel is full: it waits
            await anyio.sleep(0.1)
            got += [(t, time, m.n) for t, time, m in funnel.take_all()]
            await anyio.sleep(0.1)  # the waiting publisher got its room and delivered
            got += [(t, time, m.n) for t, time, m in funnel.take_all()]
            assert funnel.take_all() == []
        taken = {topic: tap.taken for topic, tap in funnel.taps.items()}
        return got, taken, funnel.statistics().blocked_publishes

    got, taken, blocked = anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})
    assert [(t, round(time, 6), n) for t, time, n in got] == [
        ("/a", 0.0, 0),
        ("/b", 0.1, 1),
        ("/a", 0.2, 2),
        ("/a", 0.3, 3),
    ]
    assert taken == {"/a": 3, "/b": 1}
    assert blocked == 1
