"""Replay's ordering: at each instant the recorded inputs reach the replayed actors on
the same side of their wake-ups as in the recording (no physics: JumpSource worlds)."""

from __future__ import annotations

import asyncio
import gc
from pathlib import Path

import pytest

from otonav.actors._recorder import Recorder
from otonav.msgs import Twist, Vector3
from otonav.record._reader import read_messages
from otonav.record._writer import RecordingWriter
from otonav.record.cdr import encode
from otonav.replay import ReplayInputError, replay_recording
from otonav.replay._feed import Settle, plan_instants
from otonav.replay._recording import RecordedMessage
from otonav.runtime import Actor, Input, JumpSource, Output, System, virtual_loop_factory

pytestmark = pytest.mark.unit


def _twist(x: float) -> Twist:
    return Twist(linear=Vector3(x=x))


class Source(Actor):
    """Publishes /in = 0, 1, 2, ... every 10 ms (its timer is set 10 ms ahead)."""

    out = Output("/in", Twist)

    async def run(self) -> None:
        k = 0
        while True:
            k += 1
            await self.clock.sleep_until(k * 0.01)
            await self.out.publish(_twist(float(k)))


class Sampler(Actor):
    """Every 50 ms (a timer set 50 ms ahead): publishes the newest /in it has, plus a
    gain, so a change of gain changes its output."""

    inp = Input("/in", Twist)
    out = Output("/out", Twist)

    def __init__(self, gain: float = 1.0) -> None:
        super().__init__("sampler")
        self.gain = gain

    async def run(self) -> None:
        rate = self.clock.rate(20.0)
        latest = -1.0
        while True:
            await rate.sleep()
            message = self.inp.take_latest()
            if message is not None:
                latest = message.linear.x
            await self.out.publish(_twist(latest * self.gain))


class Echo(Actor):
    """Wakes on each /in as it arrives (no timer) and publishes it doubled on /echo."""

    inp = Input("/in", Twist)
    out = Output("/echo", Twist)

    def __init__(self) -> None:
        super().__init__("echo")

    async def run(self) -> None:
        async for message in self.inp:
            await self.out.publish(_twist(2 * message.linear.x))


class Relay(Actor):
    """Every 30 ms, re-publishes the newest /in as it is, without looking at it."""

    inp = Input("/in", Twist)
    out = Output("/relayed", Twist)

    def __init__(self) -> None:
        super().__init__("relay")

    async def run(self) -> None:
        rate = self.clock.rate(1 / 0.03)
        while True:
            await rate.sleep()
            message = self.inp.take_latest()
            if message is not None:
                await self.out.publish(message)


def _record(path: Path) -> None:
    async def main() -> None:
        loop = asyncio.get_running_loop()
        with RecordingWriter(path) as writer:
            async with System([Recorder(writer), Source(), Sampler(), Echo(), Relay()]):
                await asyncio.sleep(1.0)
            assert loop.time() == pytest.approx(1.0)

    with asyncio.Runner(loop_factory=virtual_loop_factory(JumpSource(0.002))) as runner:
        runner.run(main())


def test_the_recording_has_both_orders_and_the_replay_reproduces_them(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    _record(path)
    rows = [(topic, round(t, 6)) for topic, t, _m in read_messages(path)]
    # At some shared instants the sampler woke before that instant's /in, at others
    # after (its deadlines k * 0.05 are float noise above some of the source's).
    before = after = 0
    for i, (topic, t) in enumerate(rows):
        if topic == "/out" and i + 1 < len(rows) and rows[i + 1] == ("/in", t):
            before += 1
        if topic == "/out" and i > 0 and rows[i - 1] == ("/in", t):
            after += 1
    assert before > 0
    assert after > 0

    result = replay_recording(path, [Sampler()])
    assert result.byte_identical, result.first_divergence
    assert result.passed
    assert result.inputs == {"/in": 100}
    assert [t.recorded for t in result.topics] == [20]


def test_actors_woken_by_arrivals_and_relays_replay_identically(tmp_path: Path) -> None:
    # Between two sampler wake-ups the feeder delivers several /in instants at once when
    # nothing can tell; an actor woken by each arrival can, and must see each at its tick.
    path = tmp_path / "run.mcap"
    _record(path)
    for nodes in ([Echo()], [Relay()], [Sampler(), Echo(), Relay()]):
        result = replay_recording(path, nodes)
        assert result.byte_identical, (nodes, result.first_divergence)
        assert all(t.recorded >= 20 for t in result.topics), result.topics
    # The relayed messages are the recorded inputs themselves, decoded when relayed.
    relayed = replay_recording(path, [Relay()]).replayed
    assert {type(r.message) for r in relayed} == {Twist}


def test_a_changed_actor_diverges_at_its_first_different_output(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    _record(path)
    result = replay_recording(path, [Sampler(gain=2.0)])
    assert not result.passed
    first = result.first_divergence
    assert first is not None
    assert (first.topic, first.kind, first.field) == ("/out", "content", "linear.x")
    assert first.replayed == 2 * first.recorded != first.recorded
    # Within a tolerance larger than every difference, it is the same.
    assert replay_recording(path, [Sampler(gain=1.0 + 1e-12)], tolerance=1e-6).passed


def _msg(topic: str, t: float) -> RecordedMessage:
    return RecordedMessage(topic, round(t * 1e9), encode(_twist(t)))


def test_plan_settles_only_where_input_follows_an_output() -> None:
    a1, i1, i2, b1 = _msg("/a", 0.1), _msg("/in", 0.1), _msg("/in", 0.1), _msg("/b", 0.1)
    i3 = _msg("/in", 0.2)
    i4, a2 = _msg("/in", 0.3), _msg("/a", 0.3)
    instants = plan_instants(
        [a1, i1, i2, b1, i3, i4, a2], {"/in"}, {"/a": {"A"}, "/b": {"B"}}, rate=500.0
    )
    assert [(i.tick, i.steps, i.last) for i in instants] == [
        (50, (Settle(frozenset({"A"})), i1, i2), False),  # B ran after: nothing to hold
        (100, (i3,), False),
        (150, (i4, Settle(frozenset({"A"}))), True),  # the end: A runs, then it stops
    ]


def test_plan_marks_instants_where_every_actor_ran_before_the_inputs() -> None:
    a1, i1, b1 = _msg("/a", 0.1), _msg("/in", 0.1), _msg("/b", 0.1)
    a2, b2, i2 = _msg("/a", 0.2), _msg("/b", 0.2), _msg("/in", 0.2)
    i3, a3 = _msg("/in", 0.3), _msg("/a", 0.3)
    messages = [a1, i1, b1, a2, b2, i2, i3, a3]
    publishers = {"/a": {"A"}, "/b": {"B"}}
    both = plan_instants(messages, {"/in"}, publishers, rate=500.0, actors=["A", "B"])
    # 0.1: B ran after the input (hold B back); 0.2: both ran first (deliver at idle).
    assert [(i.holds, i.after_idle) for i in both] == [(True, False), (True, True), (True, False)]
    only_a = plan_instants([a1, i1, i3, a3], {"/in"}, {"/a": {"A"}}, rate=500.0, actors=["A"])
    assert [(i.holds, i.after_idle) for i in only_a] == [(True, True), (True, False)]


class ThresholdSpy(Sampler):
    """A sampler that notes the garbage collector's thresholds while it runs."""

    seen: tuple[int, int, int] | None = None

    async def run(self) -> None:
        ThresholdSpy.seen = gc.get_threshold()
        await super().run()


def test_a_replay_collects_garbage_less_often_and_restores_the_collector(
    tmp_path: Path,
) -> None:
    path = tmp_path / "run.mcap"
    _record(path)
    before = gc.get_threshold()
    result = replay_recording(path, [ThresholdSpy()])
    assert result.byte_identical, result.first_divergence
    assert ThresholdSpy.seen is not None
    assert ThresholdSpy.seen[0] >= 10_000 > before[0]
    assert gc.get_threshold() == before
    with pytest.raises(ReplayInputError):
        replay_recording(tmp_path / "missing.mcap", [Sampler()])
    assert gc.get_threshold() == before
