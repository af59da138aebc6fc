"""The wiring and live statistics of a system as plain data (for code, CLI and docs)."""

from __future__ import annotations

from dataclasses import dataclass

from otonav.runtime._events import ActorStatus
from otonav.runtime._mailbox import Bus, MailboxStatistics


@dataclass(frozen=True, slots=True)
class PublisherInfo:
    actor: str
    port: str
    qos: str
    published: int


@dataclass(frozen=True, slots=True)
class SubscriptionInfo:
    actor: str
    port: str
    qos: str
    statistics: MailboxStatistics


@dataclass(frozen=True, slots=True)
class TopicInfo:
    name: str
    type: str
    publishers: tuple[PublisherInfo, ...]
    subscriptions: tuple[SubscriptionInfo, ...]
    ros_type: str = ""
    """The ROS 2 type name (``nav_msgs/msg/Odometry``) when the message declares one."""


@dataclass(frozen=True, slots=True)
class ActorInfo:
    name: str
    kind: str
    status: ActorStatus
    restarts: int
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]


@dataclass(frozen=True, slots=True)
class Graph:
    """Actors (with the topics they read and write) and topics (with their ends)."""

    actors: tuple[ActorInfo, ...]
    topics: tuple[TopicInfo, ...]

    def topic(self, name: str) -> TopicInfo:
        for topic in self.topics:
            if topic.name == name:
                return topic
        raise KeyError(f"no topic '{name}'; topics: {[t.name for t in self.topics]}")


def build_graph(bus: Bus, actors: dict[str, tuple[str, ActorStatus, int]]) -> Graph:
    topics: list[TopicInfo] = []
    inputs: dict[str, list[str]] = {name: [] for name in actors}
    outputs: dict[str, list[str]] = {name: [] for name in actors}
    for topic in bus.topics.values():
        pubs = tuple(
            PublisherInfo(p.endpoint.actor, p.endpoint.port, str(p.qos), p.published)
            for p in topic.publishers
        )
        subs = tuple(
            SubscriptionInfo(s.endpoint.actor, s.endpoint.port, str(s.qos), s.statistics())
            for s in topic.subscriptions
        )
        for p in pubs:
            outputs.setdefault(p.actor, []).append(topic.name)
        for s in subs:
            inputs.setdefault(s.actor, []).append(topic.name)
        kind = topic.msg_type
        ros_type = str(getattr(kind, "ros_type", "") or "")
        python_type = f"{kind.__module__}.{kind.__qualname__}"
        topics.append(TopicInfo(topic.name, python_type, pubs, subs, ros_type))
    infos = tuple(
        ActorInfo(name, kind, status, restarts, tuple(inputs[name]), tuple(outputs[name]))
        for name, (kind, status, restarts) in actors.items()
    )
    return Graph(infos, tuple(topics))
