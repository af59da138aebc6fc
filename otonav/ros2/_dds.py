"""The only module that imports ``cyclonedds`` (the optional extra ``otonav[ros2]``).

A :class:`Participant` on one DDS domain makes raw writers and readers: a writer takes
the CDR bytes of :func:`otonav.record.cdr.encode` (encapsulation header included) and
hands them to Cyclone unchanged (``ddspy_write``); a reader returns the bytes of each
sample as they came (``ddspy_take``), for :func:`otonav.record.cdr.decode`. So a
message is encoded once, by the encoder the recordings use, and never goes through
Cyclone's Python serializer.

Cyclone still needs a type for each topic: its name is what matches a ROS 2 endpoint,
and its XTypes description is sent in discovery. :func:`idl_type` builds one from the
same layouts as our encoder (:func:`otonav.record._schemas.layout_for`), so the two
agree: the gate checks that Cyclone's own deserializer reads our bytes.

``cyclonedds`` ships no stubs for much of this: ``Any`` stays inside this module.
"""

from __future__ import annotations

import functools
import math
import threading
from collections.abc import Callable
from typing import Any, Final

from cyclonedds import _clayer
from cyclonedds.core import InstanceState, Listener, SampleState, ViewState
from cyclonedds.domain import Domain, DomainParticipant
from cyclonedds.idl import IdlStruct, make_idl_struct
from cyclonedds.idl import types as t
from cyclonedds.internal import dds_infinity
from cyclonedds.pub import DataWriter
from cyclonedds.qos import Policy, Qos
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic

from otonav.msgs import Message
from otonav.record._schemas import SEQUENCE, layout_for
from otonav.ros2._naming import DdsQos, dds_type_name

__all__ = ("GraphWriter", "Participant", "RawReader", "RawWriter", "idl_type")

_PRIMITIVES: Final[dict[str, Any]] = {
    "bool": bool,
    "byte": t.byte,
    "char": t.uint8,  # ROS 2 maps char to uint8
    "int8": t.int8,
    "uint8": t.uint8,
    "int16": t.int16,
    "uint16": t.uint16,
    "int32": t.int32,
    "uint32": t.uint32,
    "int64": t.int64,
    "uint64": t.uint64,
    "float32": t.float32,
    "float64": t.float64,
    "string": str,
}
_ANY_SAMPLE: Final = SampleState.Any | ViewState.Any | InstanceState.Any
_NO_WAIT: Final = 0
"""max_blocking_time of reliable writers: a write that would block fails instead (counted
as a drop); the loop never waits for a DDS reader."""


@functools.cache
def idl_type(message: type[Message]) -> Any:
    """A Cyclone IDL struct named like ROS 2's type (``pkg::msg::dds_::Name_``), with the
    fields of ``message``'s layout in order."""
    fields: dict[str, Any] = {}
    for field in layout_for(message).fields:
        base = _PRIMITIVES[field.type] if isinstance(field.type, str) else idl_type(field.type)
        if field.array is None:
            fields[field.name] = base
        elif field.array == SEQUENCE:
            fields[field.name] = t.sequence[base]
        else:
            fields[field.name] = t.array[base, field.array]
    if not fields:  # rosidl's placeholder for an empty message
        fields["structure_needs_at_least_one_member"] = t.uint8
    name = message.ros_type.replace("/", "_")
    cls: type[IdlStruct] = make_idl_struct(name, dds_type_name(message), fields)
    return cls


def _qos(policy: DdsQos, *, reader: bool) -> Any:
    history = Policy.History.KeepLast(policy.depth)
    policies: list[Any] = [
        history,
        Policy.Reliability.Reliable(dds_infinity if reader else _NO_WAIT)
        if policy.reliable
        else Policy.Reliability.BestEffort,
        Policy.Liveliness.Automatic(dds_infinity),
        Policy.Userdata(policy.user_data),
        Policy.DataRepresentation(use_cdrv0_representation=True),
    ]
    if policy.transient_local:
        policies += [
            Policy.Durability.TransientLocal,
            Policy.DurabilityService(0, history, -1, -1, -1),
        ]
    else:
        policies.append(Policy.Durability.Volatile)
    # Never match our own endpoints, on either side: a writer matched by the bridge's own
    # reader of the same topic (/goal is both an input and mirrored) counted as a peer,
    # and --ros2-wait let the run start before any node had matched.
    policies.append(Policy.IgnoreLocal.Participant)
    if not reader:
        policies.append(Policy.WriterDataLifecycle(autodispose=False))
    return Qos(*policies)


class _Changes(threading.Condition):
    """Notified whenever an endpoint gains or loses a remote match or data arrives;
    ``matches`` counts the match changes (for :meth:`Participant.wait_quiet`)."""

    def __init__(self) -> None:
        super().__init__()
        self.matches = 0


class _Matched:
    """A count of matched remote endpoints, kept by Cyclone's listener thread."""

    def __init__(self, changed: _Changes) -> None:
        self.count = 0
        self.changed = changed

    def update(self, count: int) -> None:
        with self.changed:
            self.count = count
            self.changed.matches += 1
            self.changed.notify_all()


class RawWriter:
    """Writes CDR bytes on one DDS topic."""

    def __init__(self, participant: Any, topic: Any, policy: DdsQos, changed: _Changes) -> None:
        self.matched = _Matched(changed)
        listener = Listener(
            on_publication_matched=lambda _w, status: self.matched.update(status.current_count)
        )
        self._writer = DataWriter(participant, topic, qos=_qos(policy, reader=False))
        self._writer.set_listener(listener)
        self._listener = listener  # Cyclone holds a C pointer: keep the object alive
        self.matched.update(len(self._writer.get_matched_subscriptions()))
        self._ref: int = self._writer._ref

    def write(self, data: bytes) -> bool:
        """Hand ``data`` (encapsulation header + payload) to DDS; False if refused."""
        if len(data) & 3:  # Cyclone wants whole 4-byte words, as its own writer pads
            data = data + bytes(-len(data) & 3)
        return int(_clayer.ddspy_write(self._ref, data)) >= 0

    def wait_for_acks(self, timeout: float) -> bool:
        """Block until every matched reliable reader acknowledged what was written, at
        most ``timeout`` wall seconds; whether they all did. (Through the C call:
        cyclonedds' ``DataWriter.wait_for_acks`` raises AttributeError on a timeout.)"""
        return int(self._writer._wait_for_acks(self._ref, int(timeout * 1e9))) == 0


class RawReader:
    """Takes the CDR bytes of each sample that arrives on one DDS topic."""

    def __init__(self, participant: Any, topic: Any, policy: DdsQos, changed: _Changes) -> None:
        self.matched = _Matched(changed)
        self.arrivals = 0
        """Times data arrived (Cyclone's listener thread counts, under ``changed``)."""
        self._changed = changed
        listener = Listener(
            on_subscription_matched=lambda _r, status: self.matched.update(status.current_count),
            on_data_available=lambda _r: self._arrived(),
        )
        self._reader = DataReader(participant, topic, qos=_qos(policy, reader=True))
        self._reader.set_listener(listener)
        self._listener = listener
        self.matched.update(len(self._reader.get_matched_publications()))
        self._ref: int = self._reader._ref

    def _arrived(self) -> None:
        with self._changed:
            self.arrivals += 1
            self._changed.notify_all()

    def take(self, limit: int = 64) -> list[bytes]:
        """Every valid sample waiting (at most ``limit``), oldest first; never waits."""
        taken = _clayer.ddspy_take(self._ref, _ANY_SAMPLE, limit)
        if isinstance(taken, int):
            return []
        return [bytes(data) for data, info in taken if info.valid_data]


_GID: Final = make_idl_struct(
    "Gid", "rmw_dds_common::msg::dds_::Gid_", {"data": t.array[t.uint8, 16]}
)
_NODE: Final = make_idl_struct(
    "NodeEntitiesInfo",
    "rmw_dds_common::msg::dds_::NodeEntitiesInfo_",
    {
        "node_namespace": t.bounded_str[256],
        "node_name": t.bounded_str[256],
        "reader_gid_seq": t.sequence[_GID],
        "writer_gid_seq": t.sequence[_GID],
    },
)
_PARTICIPANT_INFO: Final = make_idl_struct(
    "ParticipantEntitiesInfo",
    "rmw_dds_common::msg::dds_::ParticipantEntitiesInfo_",
    {"gid": _GID, "node_entities_info_seq": t.sequence[_NODE]},
)
_PARTICIPANT_INFO_HASH: Final = (
    b"typehash=RIHS01_91a0593bacdcc50ea9bdcf849a938b128412cc1ea821245c663bcd26f83c295e;"
)
"""rmw_dds_common/msg/ParticipantEntitiesInfo's type hash (the same in Jazzy and Kilted)."""

Node = tuple[str, str, list["RawReader"], list["RawWriter"]]
"""(namespace, name, its readers, its writers)."""


def _gid(entity: Any) -> Any:
    return _GID(data=list(entity.guid.bytes))  # the 16-byte DDS GUID, as both rmws


class GraphWriter:
    """``ros_discovery_info``: which ROS 2 nodes this participant holds and which of its
    endpoints belong to each (rmw_dds_common's ParticipantEntitiesInfo; reliable,
    transient local, keep last 1, as rmw_fastrtps and rmw_cyclonedds write it). It is
    how ``get_node_names_and_namespaces()`` and ``ros2 node list`` see nodes."""

    def __init__(self, participant: Any, made: list[Any]) -> None:
        self._participant = participant
        topic = Topic(participant, "ros_discovery_info", _PARTICIPANT_INFO)
        # A latched topic's writer, as every other writer here is made.
        policy = DdsQos(
            reliable=True, depth=1, transient_local=True, user_data=_PARTICIPANT_INFO_HASH
        )
        self._writer = DataWriter(participant, topic, qos=_qos(policy, reader=False))
        made += [topic, self._writer]

    def publish(self, nodes: list[Node]) -> None:
        """Announce ``nodes`` (replacing what was announced before)."""
        self._writer.write(
            _PARTICIPANT_INFO(
                gid=_gid(self._participant),
                node_entities_info_seq=[
                    _NODE(
                        node_namespace=namespace,
                        node_name=name,
                        reader_gid_seq=[_gid(reader._reader) for reader in readers],
                        writer_gid_seq=[_gid(writer._writer) for writer in writers],
                    )
                    for namespace, name, readers, writers in nodes
                ],
            )
        )


class Participant:
    """One DDS domain participant: its topics, writers and readers."""

    def __init__(self, domain_id: int, config: str | None) -> None:
        # A domain made with this configuration (ours, then CYCLONEDDS_URI's: naming.py).
        self._domain = Domain(domain_id, config) if config is not None else None
        self._participant = DomainParticipant(domain_id)
        self._topics: dict[str, Any] = {}
        self._made: list[Any] = [self._participant]
        self.changed = _Changes()
        """Notified whenever a writer or reader gains or loses a remote match."""
        self.closed = False

    def _topic(self, name: str, message: type[Message]) -> Any:
        topic = self._topics.get(name)
        if topic is None:
            topic = self._topics[name] = Topic(self._participant, name, idl_type(message))
            self._made.append(topic)
        return topic

    def writer(self, name: str, message: type[Message], policy: DdsQos) -> RawWriter:
        writer = RawWriter(self._participant, self._topic(name, message), policy, self.changed)
        self._made.append(writer._writer)
        return writer

    def graph(self) -> GraphWriter:
        """The writer of ``ros_discovery_info`` (see :class:`GraphWriter`)."""
        return GraphWriter(self._participant, self._made)

    def drop(self, writer: RawWriter) -> None:
        """Delete ``writer`` now (its readers see it go)."""
        if writer._writer in self._made:
            self._made.remove(writer._writer)
            writer._writer.__del__()

    def reader(self, name: str, message: type[Message], policy: DdsQos) -> RawReader:
        reader = RawReader(self._participant, self._topic(name, message), policy, self.changed)
        self._made.append(reader._reader)
        return reader

    def wait(self, ready: Callable[[], bool], timeout: float) -> bool:
        """Block (a worker thread, never the loop) until ``ready()`` after some match
        changed or some data arrived, at most ``timeout`` wall seconds; whether it became
        ready."""
        with self.changed:
            return self.changed.wait_for(ready, timeout)

    def wait_quiet(self, quiet: float, limit: float) -> bool:
        """Block (a worker thread) until no endpoint gained or lost a match for ``quiet``
        wall seconds, at most about ``limit``; whether it got quiet. Discovery announces a
        peer's endpoints one by one: matching the first ones does not mean the rest."""
        for _ in range(max(1, math.ceil(limit / quiet))):
            with self.changed:
                seen = self.changed.matches

                def moved(seen: int = seen) -> bool:
                    return self.changed.matches != seen or self.closed

                if not self.changed.wait_for(moved, quiet):
                    return True
                if self.closed:
                    return False
        return False

    def close(self) -> None:
        """Delete every entity made here, then the participant and the domain: Cyclone's
        Python objects keep themselves alive in a class-wide table until deleted, so
        dropping references would leak them (idempotent)."""
        if self.closed:
            return
        with self.changed:  # a waiting worker thread sees it and returns
            self.closed = True
            self.changed.notify_all()
        for entity in reversed(self._made):
            entity.__del__()
        self._made.clear()
        self._topics.clear()
        if self._domain is not None:
            self._domain.__del__()
            self._domain = None
