"""The ROS 2 bridge: otonav's topics on DDS as a ROS 2 node on Cyclone DDS has them.

Out: every topic of the system is mirrored on its DDS topic
(``/odom`` -> ``rt/odom``, type ``nav_msgs::msg::dds_::Odometry_``, QoS as the topic's
publishers offer it, mapped as rmw_cyclonedds maps it: :mod:`otonav.ros2._naming`). A
mirror is a mailbox that writes as the message is published: the CDR encoding of the
recordings, handed to Cyclone, no copy through a queue. A topic nobody on DDS reads is
not even encoded (latched ones are, for readers that come later).

In: the section's ``inputs`` (``/goal`` by default; add ``/cmd_vel_nav`` or ``/cmd_vel``
to drive the robot from your own nodes) are read from DDS every ``period`` s of sim time,
decoded and published on the bus by a publisher of the bridge's own, with the QoS the
topic's publishers offer (a latched /goal stays latched). The DDS reader requests what a
ROS 2 publisher offers by default (reliable, volatile), so ``ros2 topic pub`` and RViz
match it; a best-effort publisher does not (ROS 2's rule).

Time: the bridge works on either loop; ``otonav run --ros2`` paces it to the wall clock
(docs/adr/0047). With ``wait`` (``--ros2-wait``) the start holds sim time until
DDS peers are matched, so neither a virtual-time run (a test) nor a node started a
moment later races past them.

Lockstep (the section's ``lockstep``, virtual time only; docs/adr/0065): ROS 2 nodes run
in otonav's time, as fast as they can follow. /clock is written to DDS last at each
instant, once every other actor has published what it had for that instant (the loop's
idle watcher); at each instant where a declared answer is due (``period`` multiples),
sim time holds until a new sample arrived on each due topic, then takes it in, or the
run fails after ``lockstep_timeout`` wall seconds naming the topic nobody answered.
"""

from __future__ import annotations

import asyncio
import contextlib
import os
import re
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

import anyio

from otonav.actors import _topics as topics
from otonav.msgs import (
    Clock,
    Header,
    Log,
    Message,
    Parameter,
    ParameterEvent,
    ParameterValue,
    Time,
    Twist,
    TwistStamped,
)
from otonav.record.cdr import decode, encode
from otonav.ros2._naming import (
    DdsQos,
    Discovery,
    Ros2Error,
    dds_qos,
    dds_topic,
    discovery,
    domain_id,
)
from otonav.ros2._parameters import rclpy_available
from otonav.runtime import Actor, Bus, Durability, Output, QoS, Reliability, run_blocking
from otonav.runtime._mailbox import Endpoint, Publisher, Subscription, Topic
from otonav.stack._config import Ros2Config
from otonav.stack._door import Refusals, refusal

if TYPE_CHECKING:
    from otonav.ros2._dds import GraphWriter, Participant, RawReader, RawWriter
    from otonav.ros2._parameters import ParameterNodes

__all__ = ("LockstepTimeout", "Ros2Bridge", "Ros2Statistics")


class LockstepTimeout(RuntimeError):
    """A ROS 2 node did not answer within ``lockstep_timeout``: the run fails with it."""


class Ros2Statistics(NamedTuple):
    """Counters of a bridge."""

    sent: int
    """Messages written to DDS."""
    unread: int
    """Messages not encoded: nobody on DDS subscribed to their topic."""
    refused: int
    """Writes DDS refused (a reliable reader too slow: never waited for)."""
    received: int
    """Messages taken from DDS and published on the bus."""
    rejected: int
    """Messages from DDS refused at the door (not the topic's type, a NaN, a goal beyond
    the world: ``otonav.stack._door``) or dropped because the topic was full."""


_DISCOVERY_QUIET = 0.5
"""Wall seconds without a new DDS match before a lockstep run starts."""

_MIRROR_QOS = QoS(Reliability.BEST_EFFORT, depth=1)
"""Matches every publisher (ROS 2 rules): mirroring never makes wiring fail."""


class _Mirror(Subscription[Any]):
    """A mailbox that writes each message to its DDS topic as it is published (or, when
    ``deferred``, keeps the latest for the bridge to write once the instant settled)."""

    __slots__ = (
        "convert",
        "deferred",
        "latched",
        "offered",
        "pending",
        "refused",
        "sent",
        "unacked",
        "unread",
        "writer",
    )

    def __init__(self, topic: Topic[Any], endpoint: Endpoint) -> None:
        super().__init__(topic.name, topic.msg_type, _MIRROR_QOS, endpoint)
        self.writer: RawWriter | None = None
        self.offered: QoS | None = None
        """The QoS the writer offers: the topic's publishers' when it was made."""
        self.latched = False
        self.deferred = False
        self.pending: Any = None
        self.convert: Callable[[Any], Any] | None = None
        """What the message becomes on DDS (a Twist stamped), or None: as it is."""
        self.unacked: set[_Mirror] | None = None
        """In lockstep, for a reliable writer: where it notes itself once it wrote, so the
        next answered /clock waits for the node's acknowledgement."""
        self.sent = self.unread = self.refused = 0

    def _offer(self, message: Any) -> bool:
        self.received += 1
        if self.deferred:
            self.pending = message
        else:
            self.write(message)
        return True

    def write(self, message: Any) -> None:
        writer = self.writer
        if writer is None or not (writer.matched.count or self.latched):
            self.unread += 1
        elif writer.write(encode(message if self.convert is None else self.convert(message))):
            self.sent += 1
            if self.unacked is not None:
                self.unacked.add(self)
        else:
            self.refused += 1

    def _full(self) -> bool:
        return False


@dataclass(slots=True)
class _Input:
    name: str
    msg_type: type[Message]
    publisher: Publisher[Any]
    qos: DdsQos
    wire_type: type[Message]
    """The type on DDS (TwistStamped for a Twist topic with ``twist_stamped``)."""
    reader: RawReader | None = None


def _offered(topic: Topic[Any]) -> QoS:
    """The QoS a topic's publishers offer; with none yet, what serves its subscribers."""
    if topic.publishers:
        return topic.publishers[0].qos
    if any(s.qos.durability is Durability.TRANSIENT_LOCAL for s in topic.subscriptions):
        return QoS(depth=1, durability=Durability.TRANSIENT_LOCAL)
    return QoS()


class Ros2Bridge(Actor):
    """Mirrors topics out to DDS and takes inputs in (see the module docstring)."""

    rosout = Output(topics.ROSOUT, Log, topics.ROSOUT_QOS)
    parameter_events = Output(topics.PARAMETER_EVENTS, ParameterEvent, topics.PARAMETER_EVENTS_QOS)

    def __init__(
        self,
        options: Ros2Config | None = None,
        *,
        base_frame: str = "base_link",
        period: float = 0.01,
        env: Mapping[str, str] | None = None,
        name: str = "ros2",
    ) -> None:
        """The bridge the stack config's ``ros2`` section asks for (``enabled`` aside);
        ``base_frame``: what a stamped Twist going out says (``robot.frames.base``);
        ``period``: s of sim time between two reads of the inputs. With ``wait``, sim time
        holds at the start until a ROS 2 node subscribed to an output or publishes an input
        (in lockstep: every answer has a publisher and /clock a subscriber), then until no
        endpoint matched for 0.5 s (discovery settled), at most ``wait`` wall s each."""
        super().__init__(name)
        env = os.environ if env is None else env
        self.options = options = options if options is not None else Ros2Config()
        for answer in options.lockstep:
            if answer.topic not in options.inputs:
                raise Ros2Error(
                    f"ros2.lockstep {answer.topic}: not an input of the bridge, so no node can "
                    f"answer on it; add --ros2-in {answer.topic} (inputs: "
                    f"{', '.join(options.inputs)})"
                )
        self.base_frame, self.period = base_frame, period
        self.domain_id = domain_id(options.domain_id, env)
        self.discovery: Discovery = discovery(env, lockstep=bool(options.lockstep))
        try:
            from otonav.ros2._dds import Participant
        except ImportError:
            raise Ros2Error("--ros2 needs the ros2 extra: pip install 'otonav[ros2]'") from None
        self.participant: Participant = Participant(self.domain_id, self.discovery.config)
        self._mirrors: dict[str, _Mirror] = {}
        self._inputs: list[_Input] = []
        self._bus: Bus | None = None
        self._started = False
        self.received = 0
        self.refusals = Refusals(lambda text: self._log(Log.WARN, text))
        """Messages from DDS the door refused (not the topic's type, a NaN, a goal
        beyond the world: ``otonav.stack._door``) or dropped (the topic was full), by
        source."""
        self._clock_mirror: _Mirror | None = None
        self._armed: asyncio.Event | None = None
        """Set by the idle watcher once a lockstep instant settled and /clock was written."""
        self._baselines: list[int] = []
        """Each input's DDS arrivals just before the armed instant's /clock was written."""
        self._remove_watcher: Any = None
        self._unacked: set[_Mirror] = set()
        self.unacknowledged = 0
        """Answered instants whose reliable samples a node did not acknowledge in time."""
        self._unmatched = ""
        """The warning of a wait for peers that timed out, logged once the run starts."""
        self._graph: GraphWriter | None = None
        self._parameter_actors: tuple[Actor, ...] = ()
        self.parameter_nodes: ParameterNodes | None = None
        """The rclpy nodes serving the actors' parameters (None: rclpy not importable,
        or :meth:`serve_parameters` not called)."""

    # -- wiring -----------------------------------------------------------------------

    def on_wired(self, bus: Bus) -> None:
        self._bus = bus
        for name in self.options.inputs:
            used = bus.topics.get(name)
            if used is None:
                known = ", ".join(sorted(bus.topics))
                raise Ros2Error(f"--ros2-in {name}: no such topic in this system ({known})")
            qos = _offered(used)
            endpoint = Endpoint(self.name, f"in{name}")
            publisher = bus.publisher(name, used.msg_type, qos, endpoint=endpoint)
            # A ROS 2 publisher's default offer: reliable, volatile.
            wire = self._wire_type(used.msg_type)
            wanted = dds_qos(QoS(depth=qos.depth), wire)
            self._inputs.append(_Input(name, used.msg_type, publisher, wanted, wire))
        for topic in list(bus.topics.values()):
            self._mirror(topic)
        bus.add_topic_listener(self._mirror)
        if self.options.lockstep:
            clock = self._mirrors.get(topics.CLOCK)
            if clock is None:
                raise Ros2Error("ros2.lockstep: the system publishes no /clock to step by")
            clock.deferred = True  # written last at each instant: _settled
            self._clock_mirror = clock
        if self.options.wait is not None:
            self._open_endpoints()
            self._wait_for_peers(self.options.wait)

    def _mirror(self, topic: Topic[Any]) -> None:
        if topic.name in self._mirrors:
            return
        mirror = _Mirror(topic, Endpoint(self.name, f"out{topic.name}"))
        topic.subscriptions.append(mirror)
        self._mirrors[topic.name] = mirror
        if self._bus is not None and self._started:
            # A topic made after the start (a test's latched /goal): its first publisher
            # is added just after this call, and the writer must offer what it offers
            # (a transient-local reader never matches a volatile writer). Opened once it
            # exists, before sim time moves on.
            asyncio.get_running_loop().call_soon(self._open_late, topic, mirror)

    def _open_late(self, topic: Topic[Any], mirror: _Mirror) -> None:
        if mirror.writer is not None or not self._started:
            return
        self._open_writer(topic, mirror)
        self._announce()
        if self.options.lockstep and self.options.wait is not None:
            # The nodes' readers match it a moment later; in lockstep sim time holds
            # until they did (the loop is held: nothing else may move meanwhile).
            self.participant.wait_quiet(_DISCOVERY_QUIET, self.options.wait)

    def _wire_type(self, msg_type: type[Message]) -> type[Message]:
        """The type a topic has on DDS: TwistStamped for a Twist with ``twist_stamped``."""
        return TwistStamped if self.options.twist_stamped and msg_type is Twist else msg_type

    def _stamped(self, twist: Twist) -> TwistStamped:
        clock = self._otonav_clock
        now = clock.now() if clock is not None else 0.0
        header = Header(stamp=Time.from_seconds(now), frame_id=self.base_frame)
        return TwistStamped(header=header, twist=twist)

    def _open_writer(self, topic: Topic[Any], mirror: _Mirror) -> None:
        qos = mirror.offered = _offered(topic)
        mirror.latched = qos.durability is Durability.TRANSIENT_LOCAL
        wire = self._wire_type(topic.msg_type)
        if wire is not topic.msg_type:
            mirror.convert = self._stamped
        policy = dds_qos(qos, wire)
        mirror.writer = self.participant.writer(dds_topic(topic.name), wire, policy)
        if self.options.lockstep and policy.reliable:
            mirror.unacked = self._unacked
        for publisher in topic.publishers:  # what a latched publisher already kept
            for message in publisher._history or ():
                mirror._offer(message)

    # -- running ----------------------------------------------------------------------

    def _open_endpoints(self) -> None:
        """Make the DDS writers and readers not made yet: from then on, discovery runs.
        While wiring (``--ros2-wait``), a topic nobody publishes yet gets its writer only
        when the run starts, once its publisher (the scenario's /goal) says what it offers."""
        bus = self._bus
        assert bus is not None, "on_wired comes first"
        wiring = not self._started
        for name, mirror in self._mirrors.items():
            topic = bus.topics[name]
            if mirror.writer is None and (topic.publishers or not wiring):
                self._open_writer(topic, mirror)
        for entry in self._inputs:
            if entry.reader is None:
                entry.reader = self.participant.reader(
                    dds_topic(entry.name), entry.wire_type, entry.qos
                )

    def _wait_for_peers(self, wait: float) -> None:
        """Block until the ROS 2 nodes matched (:meth:`_peers_matched`), then until no
        other endpoint matched for a moment: a node's endpoints match one by one, and a
        sample written before its reader matched is lost to it (in lockstep, its first
        answers would differ from run to run). Called while wiring, before the system
        runs, so sim time holds in every time mode (a real-time clock would run on)."""
        if not self.participant.wait(self._peers_matched, wait):
            self._unmatched = f"no ROS 2 peer matched within {wait:g} s; going on"
        else:
            self.participant.wait_quiet(_DISCOVERY_QUIET, wait)

    def _reoffer(self) -> None:
        """Writers made while wiring (``--ros2-wait``) offered what the topic's
        publishers offered then; a publisher made since (the scenario's latched /goal)
        may offer otherwise: such a writer is made again, with that QoS. The nodes'
        readers are known by now, so it matches them at once."""
        bus = self._bus
        assert bus is not None
        for name, mirror in self._mirrors.items():
            topic = bus.topics[name]
            if mirror.writer is not None and _offered(topic) != mirror.offered:
                self.participant.drop(mirror.writer)
                self._open_writer(topic, mirror)

    def _parameter_changed(self, actor: str, key: str, value: Any) -> None:
        """A set through ROS 2 took effect: say so on /parameter_events (recorded)."""
        if isinstance(value, bool):
            wire = ParameterValue(type=ParameterValue.BOOL, bool_value=value)
        elif isinstance(value, int):
            wire = ParameterValue(type=ParameterValue.INTEGER, integer_value=value)
        else:
            wire = ParameterValue(type=ParameterValue.DOUBLE, double_value=float(value))
        event = ParameterEvent(
            stamp=Time.from_seconds(self.clock.now()),
            node=f"/{_node_name(actor)}",
            changed_parameters=(Parameter(name=key, value=wire),),
        )
        with contextlib.suppress(anyio.WouldBlock):  # full: the event is not recorded
            self.parameter_events.publish_nowait(event)

    def serve_parameters(self, actors: Iterable[Actor]) -> None:
        """Serve the parameters of ``actors`` as ROS 2 parameter services once the run
        starts, when rclpy is importable (:mod:`otonav.ros2._parameters`)."""
        self._parameter_actors = tuple(actors)

    def _announce(self) -> None:
        """Every actor as a ROS 2 node on ``ros_discovery_info``, owning the DDS writer of
        each topic it publishes and the DDS reader of each input it subscribes to (the
        bridge: its inputs' readers), so ``ros2 node list`` and
        ``get_publisher_names_and_types_by_node`` show the stack as nodes."""
        bus = self._bus
        if bus is None or self._graph is None:
            return
        readers: dict[str, list[RawReader]] = {self.name: []}
        writers: dict[str, list[RawWriter]] = {self.name: []}
        inputs = {e.name: e.reader for e in self._inputs if e.reader is not None}
        for name, topic in bus.topics.items():
            mirror = self._mirrors.get(name)
            for publisher in topic.publishers:
                owned = writers.setdefault(publisher.endpoint.actor, [])
                if mirror is not None and mirror.writer is not None:
                    owned.append(mirror.writer)
                readers.setdefault(publisher.endpoint.actor, [])
            for subscription in topic.subscriptions:
                actor = subscription.endpoint.actor
                writers.setdefault(actor, [])
                owned_readers = readers.setdefault(actor, [])
                if name in inputs and actor != self.name:
                    owned_readers.append(inputs[name])
        readers[self.name] += inputs.values()
        served = self.parameter_nodes.nodes if self.parameter_nodes is not None else {}
        nodes = [
            ("/", _node_name(actor), readers[actor], writers[actor])
            for actor in writers
            if actor not in served  # rclpy's node of that name is in the graph already
        ]
        self._graph.publish(nodes)

    async def on_start(self) -> None:
        self._reoffer()
        self._started = True
        self._open_endpoints()
        if self._parameter_actors and rclpy_available():
            from otonav.ros2._parameters import ParameterNodes

            self.parameter_nodes = ParameterNodes(
                self._parameter_actors,
                domain_id=self.domain_id,
                loop=asyncio.get_running_loop(),
                node_name=_node_name,
                on_change=self._parameter_changed,
                on_refused=lambda text: self.refusals.refuse("ROS 2 parameters", text),
            )
            # rclpy's nodes put their own events on DDS: otonav's go to the recording only.
            events = self._mirrors.get(topics.PARAMETER_EVENTS)
            if events is not None and events.writer is not None:
                self.participant.drop(events.writer)
                events.writer = None
        self._graph = self.participant.graph()
        self._announce()
        if self._unmatched:
            self._log(Log.WARN, self._unmatched)
        if self.options.lockstep:
            add_watcher = getattr(asyncio.get_running_loop(), "add_idle_watcher", None)
            if add_watcher is None:
                raise Ros2Error(
                    "ros2.lockstep: needs the virtual-time loop (not with --realtime or --gui)"
                )
            self._remove_watcher = add_watcher(self._settled)
            wait = self.options.wait
            if wait is not None and not self._unmatched:
                # Writers made just now (the scenario's latched /goal, whose publisher
                # did not exist while wiring) match the node's readers a moment later:
                # sim time holds until they did, or the node's first answers would
                # depend on when its goal arrived.
                await run_blocking(self.participant.wait_quiet, _DISCOVERY_QUIET, wait)

    def _peers_matched(self) -> bool:
        if self.options.lockstep:
            answers = {answer.topic for answer in self.options.lockstep}
            clock = self._clock_mirror
            writer = clock.writer if clock is not None else None
            return all(
                e.reader is not None and e.reader.matched.count
                for e in self._inputs
                if e.name in answers
            ) and (writer is not None and writer.matched.count > 0)
        inputs = any(e.reader is not None and e.reader.matched.count for e in self._inputs)
        outputs = any(
            m.writer is not None and m.writer.matched.count for m in self._mirrors.values()
        )
        return inputs or outputs

    async def run(self) -> None:
        if self.options.lockstep:
            await self._run_lockstep()
        rate = self.clock.rate(1.0 / self.period)
        while True:
            await rate.sleep()
            self.take_inputs()

    # -- lockstep -----------------------------------------------------------------------

    def _settled(self) -> bool:
        """The loop's idle watcher in lockstep: every actor has done what it had for this
        instant. Write its /clock now, last, so a node's timer that this /clock fires sees
        the instant's /odom and /scan first; on an armed instant, note each input's
        arrivals first, then wake :meth:`_run_lockstep`. Never removed (returns False)."""
        mirror = self._clock_mirror
        if mirror is None:
            return False
        armed = self._armed
        if armed is not None and not armed.is_set():
            self._baselines = [e.reader.arrivals if e.reader else 0 for e in self._inputs]
            if mirror.pending is None:  # an answer due between two /clock ticks
                mirror.pending = Clock(clock=Time.from_seconds(self.clock.now()))
            # The node's timer this /clock fires reads the latest /odom: it must be in
            # the node's reader first. Reliable samples are acknowledged once they are
            # (heartbeats every 1 ms in lockstep: naming.LOCKSTEP_CONFIG).
            timeout = self.options.lockstep_timeout
            for unacked in self._unacked:
                writer = unacked.writer
                if (
                    writer is not None
                    and writer.matched.count
                    and not writer.wait_for_acks(timeout)
                ):
                    self.unacknowledged += 1
                    self._log(
                        Log.WARN,
                        f"lockstep: {unacked.topic} not acknowledged within {timeout:g} s "
                        f"(wall) of /clock {self.clock.now():.3f} s: the node may answer from "
                        "older data",
                    )
            self._unacked.clear()
            armed.set()
        if mirror.pending is not None:
            message, mirror.pending = mirror.pending, None
            mirror.write(message)
        return False

    async def _run_lockstep(self) -> None:
        clock = self.clock
        entries = [
            (next(e for e in self._inputs if e.name == answer.topic), answer.period)
            for answer in self.options.lockstep
        ]
        counts = [0] * len(entries)
        timeout = self.options.lockstep_timeout
        while True:
            dues = [(counts[i] + 1) * period for i, (_e, period) in enumerate(entries)]
            at = min(dues)
            await clock.sleep_until(at)
            due = [i for i, when in enumerate(dues) if when <= at + 1e-9]
            for i in due:
                counts[i] += 1
            armed = self._armed = asyncio.Event()
            await armed.wait()  # set by _settled once this instant's /clock is out
            waiting = [
                (entries[i][0], self._baselines[self._inputs.index(entries[i][0])], entries[i][1])
                for i in due
            ]

            def answered(waiting: list[tuple[_Input, int, float]] = waiting) -> bool:
                return self.participant.closed or all(
                    e.reader is not None and e.reader.arrivals > base for e, base, _p in waiting
                )

            if not await run_blocking(self.participant.wait, answered, timeout):
                silent = [
                    (e, p) for e, base, p in waiting if e.reader and e.reader.arrivals <= base
                ]
                entry, period = silent[0] if silent else (waiting[0][0], waiting[0][2])
                publishers = entry.reader.matched.count if entry.reader else 0
                raise LockstepTimeout(
                    f"lockstep: no ROS 2 node answered on {entry.name} within {timeout:g} s "
                    f"(wall) of /clock {clock.now():.3f} s ({publishers} DDS publisher(s) "
                    f"matched; a node must publish it every {period:g} s of its use_sim_time "
                    "clock)"
                )
            self.take_inputs()

    def take_inputs(self) -> None:
        """Publish on the bus what DDS publishers sent since the last call."""
        for entry in self._inputs:
            reader = entry.reader
            if reader is None:
                continue
            source = f"ROS 2 ({dds_topic(entry.name)})"
            for data in reader.take():
                try:
                    message = decode(entry.wire_type, data)
                except (ValueError, IndexError, TypeError, OverflowError) as exc:
                    first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
                    self.refusals.refuse(source, f"not a {entry.wire_type.ros_type} ({first})")
                    continue
                if isinstance(message, TwistStamped):
                    message = message.twist
                problem = refusal(message)
                if problem is not None:  # outside data, checked at the door (issue 41)
                    self.refusals.refuse(source, f"{entry.name}: {problem}")
                    continue
                try:
                    entry.publisher.publish_nowait(message)
                    self.received += 1
                except anyio.WouldBlock:  # counted as refusals are: a flood stays bounded
                    self.refusals.refuse(source, f"{entry.name}: full, dropped")

    async def on_stop(self) -> None:
        if self._remove_watcher is not None:
            self._remove_watcher()
        self.close()

    def close(self) -> None:
        """Leave the DDS domain (idempotent): ROS 2 nodes see the endpoints go."""
        for mirror in self._mirrors.values():
            mirror.writer = None
        for entry in self._inputs:
            entry.reader = None
        if self.parameter_nodes is not None:
            self.parameter_nodes.close()
        self.participant.close()

    def _log(self, level: int, text: str) -> None:
        clock = self._otonav_clock
        now = clock.now() if clock is not None else 0.0
        log = Log(stamp=Time.from_seconds(now), level=level, name=self.name, msg=text)
        with contextlib.suppress(anyio.WouldBlock):  # /rosout full: the line is lost
            self.rosout.publish_nowait(log)

    def statistics(self) -> Ros2Statistics:
        mirrors = self._mirrors.values()
        return Ros2Statistics(
            sent=sum(m.sent for m in mirrors),
            unread=sum(m.unread for m in mirrors),
            refused=sum(m.refused for m in mirrors),
            received=self.received,
            rejected=self.refusals.count,
        )


def _node_name(actor: str) -> str:
    """A ROS 2 node name for an actor (letters, digits and underscores, not a digit first)."""
    name = re.sub(r"[^A-Za-z0-9_]", "_", actor)
    return name if name and not name[0].isdigit() else f"_{name}"
