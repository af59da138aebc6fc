"""Actors: typed ports bound to topics, and plain-named lifecycle hooks.

    class Base(Actor):
        cmd_vel = Input("/cmd_vel", Twist)
        wheels = Output("/wheel_cmd", WheelCommand)

        async def run(self) -> None:
            async for twist in self.cmd_vel:
                await self.wheels.publish(...)

Ports are declared on the class and bound when a :class:`~otonav.runtime.system.System`
wires the actor; ``remap`` renames topics per instance, as ROS 2 remapping does.
Framework state lives in ``_otonav_*`` attributes so subclasses cannot clash with it.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any, Generic, TypeVar, overload

from otonav.runtime.clock import Clock
from otonav.runtime.mailbox import Bus, Publisher, Subscription
from otonav.runtime.qos import DEFAULT_QOS, QoS

M = TypeVar("M")


class _Port(Generic[M]):
    direction = ""

    def __init__(self, topic: str, msg_type: type[M], qos: QoS = DEFAULT_QOS) -> None:
        self.topic = topic
        self.msg_type = msg_type
        self.qos = qos
        self.name = ""

    def __set_name__(self, owner: type[Any], name: str) -> None:
        self.name = name

    def _bound(self, instance: Actor) -> Any:
        try:
            return instance._otonav_ports[self.name]
        except KeyError:
            raise RuntimeError(
                f"port '{self.name}' of actor '{instance.name}' is not wired yet: add the "
                "actor to a System (which wires its ports) before using it"
            ) from None


class Input(_Port[M]):
    """An input port: a mailbox on ``topic`` of messages of ``msg_type``."""

    direction = "in"

    @overload
    def __get__(self, instance: None, owner: type[Any]) -> Input[M]: ...
    @overload
    def __get__(self, instance: Actor, owner: type[Any]) -> Subscription[M]: ...
    def __get__(self, instance: Actor | None, owner: type[Any]) -> Input[M] | Subscription[M]:
        if instance is None:
            return self
        bound: Subscription[M] = self._bound(instance)
        return bound


class Output(_Port[M]):
    """An output port: a publisher on ``topic`` of messages of ``msg_type``."""

    direction = "out"

    @overload
    def __get__(self, instance: None, owner: type[Any]) -> Output[M]: ...
    @overload
    def __get__(self, instance: Actor, owner: type[Any]) -> Publisher[M]: ...
    def __get__(self, instance: Actor | None, owner: type[Any]) -> Output[M] | Publisher[M]:
        if instance is None:
            return self
        bound: Publisher[M] = self._bound(instance)
        return bound


def _snake(name: str) -> str:
    return re.sub(r"(?<!^)(?=[A-Z])", "_", name).lower()


class Actor:
    """Base class of every actor. Override ``on_start``, ``run`` and ``on_stop``.

    ``run`` is the actor's body; when it returns, the actor is done (the others go
    on). ``on_stop`` always runs, also when the system stops because another actor
    crashed.
    """

    def __init__(self, name: str | None = None, *, remap: Mapping[str, str] | None = None) -> None:
        self.name = name or _snake(type(self).__name__)
        self._otonav_remap: dict[str, str] = dict(remap or {})
        self._otonav_ports: dict[str, Any] = {}
        self._otonav_clock: Clock | None = None
        self._otonav_params: Mapping[str, Any] = {}

    @classmethod
    def ports(cls) -> list[_Port[Any]]:
        """The declared ports, in declaration order (base classes first)."""
        seen: dict[str, _Port[Any]] = {}
        for klass in reversed(cls.__mro__):
            for attr, value in vars(klass).items():
                if isinstance(value, _Port):
                    seen[attr] = value
        return list(seen.values())

    @property
    def parameters(self) -> Mapping[str, Any]:
        """The parameters the actor was launched with (``otonav graph`` lists them):
        a launched actor's validated ``Params``, as plain values; empty otherwise."""
        return self._otonav_params

    def topic_of(self, port: _Port[Any]) -> str:
        """The topic ``port`` is bound to for this instance (after remapping)."""
        return self._otonav_remap.get(port.topic, port.topic)

    @property
    def clock(self) -> Clock:
        """Sim time, for ``now()``, ``sleep_until()`` and ``rate()``."""
        if self._otonav_clock is None:
            raise RuntimeError(f"actor '{self.name}' has no clock until its System runs")
        return self._otonav_clock

    def on_wired(self, bus: Bus) -> None:
        """Called once, synchronously, when the System has wired every actor's ports:
        for actors that attach to topics dynamically (a recorder)."""

    async def on_start(self) -> None:
        """Called once before ``run`` (and again before each restart)."""

    async def run(self) -> None:
        """The actor's body. The default does nothing (a purely passive actor)."""

    async def on_stop(self) -> None:
        """Called when the actor stops, however it stops (shielded from cancellation)."""
