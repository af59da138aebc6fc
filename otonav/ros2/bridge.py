"""The ROS 2 bridge: otonav's topics on DDS as a ROS 2 node on Cyclone DDS has them.

Out: every topic of the system (or ``Ros2Options.outputs``) is mirrored on its DDS topic
(``/odom`` -> ``rt/odom``, type ``nav_msgs::msg::dds_::Odometry_``, QoS as the topic's
publishers offer it, mapped as rmw_cyclonedds maps it: :mod:`otonav.ros2.naming`). A
mirror is a mailbox that writes as the message is published: the CDR encoding of the
recordings, handed to Cyclone, no copy through a queue. A topic nobody on DDS reads is
not even encoded (latched ones are, for readers that come later).

In: ``Ros2Options.inputs`` (``/goal`` by default; add ``/cmd_vel_nav`` or ``/cmd_vel``
to drive the robot from your own nodes) are read from DDS every ``period`` s of sim time,
decoded and published on the bus by a publisher of the bridge's own, with the QoS the
topic's publishers offer (a latched /goal stays latched). The DDS reader requests what a
ROS 2 publisher offers by default (reliable, volatile), so ``ros2 topic pub`` and RViz
match it; a best-effort publisher does not (ROS 2's rule).

Time: the bridge works on either loop; ``otonav run --ros2`` paces it to the wall clock
(docs/adr/0047). With ``wait_for_peers`` the start holds sim time until DDS peers are
matched, so a virtual-time run (a test) does not race past them.
"""

from __future__ import annotations

import contextlib
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

import anyio

from otonav.actors import topics
from otonav.msgs import Log, Message, Time
from otonav.record.cdr import encode
from otonav.record.cdr_decode import decode
from otonav.ros2.naming import (
    DdsQos,
    Discovery,
    Ros2Error,
    dds_qos,
    dds_topic,
    discovery,
    domain_id,
)
from otonav.runtime import Actor, Bus, Durability, Output, QoS, Reliability, run_blocking
from otonav.runtime.mailbox import Endpoint, Publisher, Subscription, Topic

if TYPE_CHECKING:
    from otonav.ros2.dds import Participant, RawReader, RawWriter
    from otonav.stack.config import Ros2Config

__all__ = ("Ros2Bridge", "Ros2Options", "Ros2Statistics", "bridge_for")


@dataclass(frozen=True, slots=True)
class Ros2Options:
    """What the bridge mirrors and takes, and on which DDS domain."""

    domain_id: int | None = None
    """DDS domain, 0..232 (None: ``ROS_DOMAIN_ID``, else 0)."""
    inputs: tuple[str, ...] = (topics.GOAL,)
    """Topics ROS 2 nodes may publish into the stack."""
    outputs: tuple[str, ...] | None = None
    """Topics mirrored out (None: every topic of the system)."""
    period: float = 0.01
    """s of sim time between two reads of the inputs."""
    wait_for_peers: float | None = None
    """Hold sim time at the start until every input has a DDS publisher and some output
    a DDS subscriber, for at most this many wall seconds (None: do not wait)."""

    def __post_init__(self) -> None:
        if not (self.period > 0 and math.isfinite(self.period)):
            raise Ros2Error(f"ros2.period {self.period}: must be > 0 s of sim time")
        wait = self.wait_for_peers
        if wait is not None and not (wait > 0 and math.isfinite(wait)):
            raise Ros2Error(f"--ros2-wait {wait}: must be a number of seconds > 0")
        for key, names in (("--ros2-in", self.inputs), ("ros2 outputs", self.outputs or ())):
            for name in names:
                try:
                    dds_topic(name)
                except Ros2Error as exc:
                    raise Ros2Error(f"{key} {exc}") from None


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
    """Messages from DDS that did not decode as the topic's type, or found it full."""


_MIRROR_QOS = QoS(Reliability.BEST_EFFORT, depth=1)
"""Matches every publisher (ROS 2 rules): mirroring never makes wiring fail."""


class _Mirror(Subscription[Any]):
    """A mailbox that writes each message to its DDS topic as it is published."""

    __slots__ = ("latched", "refused", "sent", "unread", "writer")

    def __init__(self, topic: Topic[Any], endpoint: Endpoint) -> None:
        super().__init__(topic.name, topic.msg_type, _MIRROR_QOS, endpoint)
        self.writer: RawWriter | None = None
        self.latched = False
        self.sent = self.unread = self.refused = 0

    def _offer(self, message: Any) -> bool:
        self.received += 1
        writer = self.writer
        if writer is None or not (writer.matched.count or self.latched):
            self.unread += 1
            return True
        if writer.write(encode(message)):
            self.sent += 1
        else:
            self.refused += 1
        return True

    def _full(self) -> bool:
        return False


@dataclass(slots=True)
class _Input:
    name: str
    msg_type: type[Message]
    publisher: Publisher[Any]
    qos: DdsQos
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

    def __init__(
        self,
        options: Ros2Options = Ros2Options(),
        *,
        env: Mapping[str, str] | None = None,
        name: str = "ros2",
    ) -> None:
        super().__init__(name)
        env = os.environ if env is None else env
        self.options = options
        self.domain_id = domain_id(options.domain_id, env)
        self.discovery: Discovery = discovery(env)
        try:
            from otonav.ros2.dds import Participant
        except ImportError:
            raise Ros2Error("--ros2 needs the ros2 extra: pip install 'otonav[ros2]'") from None
        self.participant: Participant = Participant(self.domain_id, self.discovery.config)
        self._mirrors: dict[str, _Mirror] = {}
        self._inputs: list[_Input] = []
        self._bus: Bus | None = None
        self._started = False
        self.received = 0
        self.rejected = 0

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
            wanted = dds_qos(QoS(depth=qos.depth), used.msg_type)
            self._inputs.append(_Input(name, used.msg_type, publisher, wanted))
        for topic in list(bus.topics.values()):
            self._mirror(topic)
        bus.add_topic_listener(self._mirror)

    def _mirror(self, topic: Topic[Any]) -> None:
        outputs = self.options.outputs
        if topic.name in self._mirrors or (outputs is not None and topic.name not in outputs):
            return
        mirror = _Mirror(topic, Endpoint(self.name, f"out{topic.name}"))
        topic.subscriptions.append(mirror)
        self._mirrors[topic.name] = mirror
        if self._bus is not None and self._started:
            self._open_writer(topic, mirror)

    def _open_writer(self, topic: Topic[Any], mirror: _Mirror) -> None:
        qos = _offered(topic)
        mirror.latched = qos.durability is Durability.TRANSIENT_LOCAL
        mirror.writer = self.participant.writer(
            dds_topic(topic.name), topic.msg_type, dds_qos(qos, topic.msg_type)
        )
        for publisher in topic.publishers:  # what a latched publisher already kept
            for message in publisher._history or ():
                mirror._offer(message)

    # -- running ----------------------------------------------------------------------

    async def on_start(self) -> None:
        bus = self._bus
        assert bus is not None, "on_wired comes first"
        self._started = True
        for name, mirror in self._mirrors.items():
            self._open_writer(bus.topics[name], mirror)
        for entry in self._inputs:
            entry.reader = self.participant.reader(dds_topic(entry.name), entry.msg_type, entry.qos)
        wait = self.options.wait_for_peers
        # A worker thread waits; sim time holds still meanwhile (run_blocking).
        if wait is not None and not await run_blocking(
            self.participant.wait, self._peers_matched, wait
        ):
            self._log(Log.WARN, f"no ROS 2 peer matched within {wait:g} s; going on")

    def _peers_matched(self) -> bool:
        inputs = all(e.reader is not None and e.reader.matched.count for e in self._inputs)
        outputs = any(
            m.writer is not None and m.writer.matched.count for m in self._mirrors.values()
        )
        return inputs and (outputs or not self._mirrors)

    async def run(self) -> None:
        rate = self.clock.rate(1.0 / self.options.period)
        while True:
            await rate.sleep()
            self.take_inputs()

    def take_inputs(self) -> None:
        """Publish on the bus what DDS publishers sent since the last call."""
        for entry in self._inputs:
            reader = entry.reader
            if reader is None:
                continue
            for data in reader.take():
                try:
                    message = decode(entry.msg_type, data)
                except (ValueError, IndexError, TypeError) as exc:
                    self.rejected += 1
                    first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
                    self._log(Log.WARN, f"{entry.name}: not a {entry.msg_type.ros_type} ({first})")
                    continue
                try:
                    entry.publisher.publish_nowait(message)
                    self.received += 1
                except anyio.WouldBlock:
                    self.rejected += 1
                    self._log(Log.WARN, f"{entry.name}: a ROS 2 message dropped (full)")

    async def on_stop(self) -> None:
        self.close()

    def close(self) -> None:
        """Leave the DDS domain (idempotent): ROS 2 nodes see the endpoints go."""
        for mirror in self._mirrors.values():
            mirror.writer = None
        for entry in self._inputs:
            entry.reader = None
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
            rejected=self.rejected,
        )


def bridge_for(
    section: Ros2Config,
    *,
    domain_id: int | None = None,
    inputs: Sequence[str] = (),
    env: Mapping[str, str] | None = None,
) -> Ros2Bridge:
    """The bridge the stack config's ``ros2`` section asks for (``domain_id`` and
    ``inputs`` override it: the CLI's flags). The one way every surface makes it."""
    options = Ros2Options(
        domain_id=domain_id if domain_id is not None else section.domain_id,
        inputs=tuple(inputs or section.inputs),
    )
    return Ros2Bridge(options, env=env)
