"""Re-simulate actors against a recording: bring up only them on a virtual-time loop,
feed them the recorded inputs at the recorded instants and in the recorded order, and
compare what they publish with what was recorded."""

from __future__ import annotations

import asyncio
import contextlib
import gc
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Literal

from otonav.msgs import Message
from otonav.record._writer import FORMAT_METADATA, format_difference
from otonav.replay._compare import Divergence, Replayed, TopicComparison, compare_topic
from otonav.replay._feed import Feeder, FeedSource, Gate, ReplayClock, plan_instants
from otonav.replay._nodes import build_nodes
from otonav.replay._recording import (
    RecordedMessage,
    Recording,
    ReplayInputError,
    load_recording,
    read_topics,
)
from otonav.replay._world import recorded_geometry, recorded_reach
from otonav.runtime import (
    Actor,
    ActorCrashedError,
    Durability,
    QoS,
    Reliability,
    System,
    VirtualTimeLoop,
)
from otonav.runtime._asyncio_compat import preload_anyio_backend
from otonav.runtime._funnel import Funnel
from otonav.stack import StackConfig
from otonav.stack._overrides import apply_overrides

# anyio loads its asyncio backend when the first System starts: 12 ms in a fresh
# `otonav replay` process. Loaded here, with the replay's own code, rather than inside the
# first replay's window (the span its RTF is measured over); the same for the command as
# a whole (ADR 0036; `otonav run` does the same, ADR 0027).
preload_anyio_backend()


@dataclass(slots=True)
class ReplayResult:
    """What a replay found. ``passed``: no divergence beyond the tolerance, no crash."""

    recording: Path
    nodes: tuple[str, ...]
    inputs: dict[str, int]
    """Input topic -> messages fed."""
    topics: list[TopicComparison]
    divergences: list[Divergence]
    """Every divergence beyond the tolerance, in sim-time order."""
    sim_time_s: float
    wall_time_s: float
    crash: str | None = None
    """The crash report of a replayed actor that raised (the replay stopped there)."""
    stack: StackConfig = field(default_factory=StackConfig)
    replayed: list[Replayed] = field(default_factory=list)
    cpu_time_s: float = 0.0
    """The process's CPU time over the same span as ``wall_time_s`` (on a busy machine
    the wall time follows the load, this less)."""
    format_change: str | None = None
    """What differs between the recording's ``format_version`` and this otonav's (the
    engine's order within an instant, ADR 0084); None when they are the same."""

    @property
    def passed(self) -> bool:
        return not self.divergences and self.crash is None

    @property
    def byte_identical(self) -> bool:
        return self.crash is None and all(t.byte_identical for t in self.topics)

    @property
    def first_divergence(self) -> Divergence | None:
        return self.divergences[0] if self.divergences else None

    @property
    def rtf(self) -> float:
        return self.sim_time_s / self.wall_time_s if self.wall_time_s > 0 else float("inf")


SHARED_LOG_TOPICS = frozenset({"/rosout"})
"""Output topics a replay does not compare: the recording holds every actor's lines and
the system's lifecycle events there, which a replay of some nodes cannot reproduce."""


@dataclass(frozen=True, slots=True)
class _Ports:
    inputs: dict[str, tuple[type[Message], list[QoS]]]
    outputs: dict[str, type[Message]]
    publishers_of: dict[str, set[str]]


def _ports(actors: Sequence[Actor]) -> _Ports:
    """Input topics (less those another replayed actor publishes) and output topics."""
    inputs: dict[str, tuple[type[Message], list[QoS]]] = {}
    outputs: dict[str, type[Message]] = {}
    publishers_of: dict[str, set[str]] = {}
    for actor in actors:
        for port in actor.ports():
            topic = actor.topic_of(port)
            if port.direction == "out":
                if topic in SHARED_LOG_TOPICS:
                    continue  # every actor and the system log there: not one node's output
                outputs[topic] = port.msg_type
                publishers_of.setdefault(topic, set()).add(actor.name)
            else:
                entry = inputs.setdefault(topic, (port.msg_type, []))
                entry[1].append(port.qos)
    for topic in outputs:
        inputs.pop(topic, None)
    return _Ports(inputs, outputs, publishers_of)


def _check_topics(recording: Recording, ports: _Ports, nodes: Sequence[Actor]) -> None:
    names = ", ".join(a.name for a in nodes)
    for topic, (msg_type, _qos) in {
        **ports.inputs,
        **{t: (m, []) for t, m in ports.outputs.items()},
    }.items():
        recorded = recording.types.get(topic)
        if recorded is None:
            if topic in ports.inputs:
                raise ReplayInputError(
                    f"{recording.path}: has no {topic}, which {names} reads "
                    f"({msg_type.ros_type}); recorded topics: {', '.join(sorted(recording.types))}"
                )
            continue  # an output never recorded: every replayed message is "extra"
        if recorded != msg_type.ros_type:
            raise ReplayInputError(
                f"{recording.path}: {topic} is recorded as {recorded}, but {names} uses it as "
                f"{msg_type.ros_type}"
            )


def _feed_qos(requested: list[QoS]) -> QoS:
    """What the feeder offers: enough for every subscriber (reliable; transient-local if
    any wants it). Mailbox behaviour (drop or wait) is the subscriber's own QoS."""
    durable = any(q.durability is Durability.TRANSIENT_LOCAL for q in requested)
    return QoS(
        Reliability.RELIABLE,
        depth=max(q.depth for q in requested),
        durability=Durability.TRANSIENT_LOCAL if durable else Durability.VOLATILE,
    )


@contextlib.contextmanager
def _fewer_collections() -> Iterator[None]:
    """Run the cyclic garbage collector's youngest generation every 10,000 allocations
    instead of every 700 while a replay runs (restored after). A replay allocates a few
    objects per recorded message and keeps most of them until it ends; collecting them
    over and over was ~5 ms of a ~75 ms navigator replay (CPU medians of 12, interleaved;
    as much as with the collector off). Cycles are still collected, in larger batches."""
    threshold = gc.get_threshold()
    gc.set_threshold(max(threshold[0], 10_000), *threshold[1:])
    try:
        yield
    finally:
        gc.set_threshold(*threshold)


@_fewer_collections()
def replay_recording(
    recording: str | Path,
    nodes: Sequence[str | Actor],
    *,
    overrides: Sequence[str] = (),
    stack: StackConfig | None = None,
    tolerance: float = 0.0,
    wake: Literal["timers", "recorded"] = "timers",
    wall_ceiling: float | None = 600.0,
    on_start: Callable[[asyncio.AbstractEventLoop, asyncio.Task[None]], None] | None = None,
) -> ReplayResult:
    """Replay ``nodes`` (stack actor names, ``pkg.mod:Name`` paths, or actor objects)
    against ``recording``. Their config is the recording's stored stack config (or
    ``stack``, or the defaults), with ``overrides`` (``key.path=value``) applied.

    ``wake="recorded"``: wake each actor at the instants its outputs were recorded at
    instead of its own deadlines (a recording made in real time, where wake-ups followed
    the wall clock; see :class:`~otonav.replay._feed.ReplayClock`).

    ``on_start(loop, task)``: called as the replay's task starts on its loop (to cancel
    it from a signal handler; a cancelled replay raises ``asyncio.CancelledError``).

    Raises :class:`ReplayInputError` for bad input (file, node, topic, override).
    """
    if not tolerance >= 0:
        raise ReplayInputError(f"--tolerance {tolerance}: must be a number >= 0")
    wall_start = time.perf_counter()
    cpu_start = time.process_time()
    path = Path(recording)
    meta = load_recording(path, topics=())  # metadata and types only
    config = stack or meta.stack or StackConfig()
    if overrides:
        config = apply_overrides(config, overrides)
    names = [n for n in nodes if isinstance(n, str)]
    geometry = recorded_geometry(meta, config)
    reach = recorded_reach(meta, geometry)
    built = iter(build_nodes(names, config, geometry, meta.start, reach)) if names else iter(())
    actors: list[Actor] = [next(built) if isinstance(n, str) else n for n in nodes]
    if not actors:
        raise ReplayInputError("--node: name at least one node to replay")
    ports = _ports(actors)
    _check_topics(meta, ports, actors)
    full = replace(meta, messages=read_topics(meta, [*ports.inputs, *ports.outputs]))
    source = FeedSource(config.world.timestep)
    instants = plan_instants(
        full.messages,
        ports.inputs,
        ports.publishers_of,
        source.rate,
        actors=[a.name for a in actors],
    )
    fed: dict[str, int] = dict.fromkeys(ports.inputs, 0)
    for instant in instants:
        for step in instant.steps:
            if isinstance(step, RecordedMessage):
                fed[step.topic] += 1

    replayed: list[Replayed] = []
    crash: str | None = None
    wakes: dict[str, list[int]] = {}
    if wake == "recorded":
        # A wake-up publishes each of the actor's outputs once: a topic seen again starts
        # the next wake-up, at the instant of its first message (in real time the world
        # moves on while an actor computes, so later outputs of one wake-up come later).
        bursts: dict[str, set[str]] = {a.name: set() for a in actors}
        for message in full.messages:
            for name in ports.publishers_of.get(message.topic, ()):
                burst = bursts[name]
                if not burst or message.topic in burst:
                    burst.clear()
                    wakes.setdefault(name, []).append(round(message.time_ns * source.rate / 1e9))
                burst.add(message.topic)
        for name in bursts:
            wakes.setdefault(name, [])
    elif wake != "timers":
        raise ReplayInputError(f"--wake {wake}: expected timers or recorded")

    async def main() -> None:
        loop = asyncio.get_running_loop()
        assert isinstance(loop, VirtualTimeLoop)
        task = asyncio.current_task()
        if on_start is not None and task is not None:
            on_start(loop, task)
        system = System(actors)
        publishers = {
            topic: system.publisher(topic, msg_type, _feed_qos(qos), name="replay")
            for topic, (msg_type, qos) in ports.inputs.items()
        }
        funnel = Funnel(
            system.bus, "replay", loop.time, wanted=ports.outputs.__contains__, depth=1 << 40
        )

        def drain() -> None:
            while (delivery := funnel.try_recv()) is not None:
                replayed.append(
                    Replayed(delivery.topic, round(delivery.time * 1e9), delivery.message)
                )

        gate = Gate(loop)
        feeder = Feeder(gate, source, instants, publishers)
        try:
            async with system:
                # Each actor sleeps on its own clock (the System handed out one shared
                # clock; the actors have not run yet, so none has used it).
                for actor in actors:
                    actor._otonav_clock = ReplayClock(
                        gate, actor.name, wakes=wakes.get(actor.name), rate=source.rate
                    )
                await feeder.run()
        finally:
            drain()  # once: the funnel is unbounded and stamps each output when published

    factory = lambda: VirtualTimeLoop(source, wall_ceiling=wall_ceiling)  # noqa: E731
    sim_time = 0.0
    with asyncio.Runner(loop_factory=factory) as runner:
        try:
            runner.run(main())
        except ActorCrashedError as exc:
            crash = str(exc)
        finally:
            sim_time = runner.get_loop().time()

    divergences: list[Divergence] = []
    by_topic: dict[str, list[RecordedMessage]] = {t: [] for t in ports.outputs}
    for message in full.messages:
        if message.topic in by_topic:
            by_topic[message.topic].append(message)
    fresh: dict[str, list[Replayed]] = {t: [] for t in ports.outputs}
    for r in replayed:
        fresh[r.topic].append(r)
    comparisons = [
        compare_topic(topic, msg_type, by_topic[topic], fresh[topic], tolerance, divergences)
        for topic, msg_type in sorted(ports.outputs.items())
    ]
    divergences.sort(key=lambda d: d.sim_time)  # stable: per topic, then by time
    return ReplayResult(
        path,
        tuple(a.name for a in actors),
        fed,
        comparisons,
        divergences,
        sim_time,
        time.perf_counter() - wall_start,
        crash,
        config,
        replayed,
        time.process_time() - cpu_start,
        recording_format_change(meta.metadata),
    )


def recording_format_change(metadata: dict[str, dict[str, str]]) -> str | None:
    """What differs between a recording's format (its metadata records; none: version
    1) and the one this otonav writes; None when they are the same."""
    text = metadata.get(FORMAT_METADATA, {}).get("format_version", "1")
    return format_difference(int(text) if text.isdigit() else 0)
