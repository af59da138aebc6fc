"""Actors: typed ports bound to topics, and plain-named lifecycle hooks.

    class Base(Actor):
        cmd_vel = Input("/cmd_vel", Twist)
        wheels = Output("/wheel_cmd", WheelCommand)

        async def run(self) -> None:
            async for twist in self.cmd_vel:
                await self.wheels.publish(...)

Ports are declared on the class and bound when a :class:`~otonav.runtime._system.System`
wires the actor; ``remap`` renames topics per instance, as ROS 2 remapping does.

Names. Framework state lives in ``_otonav_*`` attributes. The public framework names
(:data:`FRAMEWORK_ATTRIBUTES`: ``name``, ``clock``, ``ports``, ``topic_of``,
``parameters``) share the subclass's namespace, as rclpy's ``Node`` methods do, because
users' nodes call ``self.clock`` and ``self.name``; so shadowing one is an
:class:`~otonav.runtime._errors.ActorDefinitionError`, never silent: a port or attribute
of that name when the class is defined, a port named like a hook (``run``), or an
instance attribute that the wiring would overwrite (a port's name) or that hides a
framework method, when the System wires the instance. (That is why the bridge's /clock
port is called ``clock_out``.) ADR 0051.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any, Final, Generic, TypeVar, overload

from pydantic import BaseModel

from otonav.runtime._clock import Clock
from otonav.runtime._errors import ActorDefinitionError
from otonav.runtime._mailbox import Bus, Publisher, Subscription
from otonav.runtime._nodelog import NodeLogger
from otonav.runtime._qos import DEFAULT_QOS, QoS

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

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.topic!r}, {self.msg_type.__name__})"

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


#: The framework's public names on every actor, with what each is. A subclass may not
#: define them (as a port or anything else), nor an instance shadow them.
FRAMEWORK_ATTRIBUTES: Final[Mapping[str, str]] = {
    "name": "the actor's name, set by Actor.__init__(name)",
    "clock": "the actor's sim-time clock",
    "ports": "the declared ports, read by the wiring",
    "topic_of": "a port's topic after remapping, read by the wiring",
    "parameters": "the parameters the actor was launched with",
    "log": "the actor's logger (self.log.info(...), to /rosout and the console)",
}


class Actor:
    """Base class of every actor. Override ``on_start``, ``run``, ``on_failure`` and
    ``on_stop``.

    ``run`` is the actor's body; when it returns, the actor is done (the others go
    on). ``on_stop`` always runs, also when the system stops because another actor
    crashed: once for every ``on_start`` that returned or raised.

    The life of an actor under its System's supervision (ADR 0051)::

        on_start -> run -> (returns: finished) ------------------------> on_stop
                        -> (raises: crashed) -> on_failure(exc) -> policy:
                               stop:    the system stops ----------------> on_stop
                               restart: on_stop -> on_start -> run ...   (same instance)

    A restart keeps the instance: the System holds the object it was given, so the
    restarted ``on_start`` and ``run`` see the attributes the crashed run left (and the
    messages still queued in its input mailboxes, which a restart does not drop).
    Whatever must start fresh is reset in ``on_start`` (or ``on_failure``), the way a
    ROS 2 lifecycle node resets in ``on_configure``.

    An exception in ``on_stop`` or ``on_failure`` is reported like a crash of the
    actor: the system stops with :class:`~otonav.runtime._errors.ActorCrashedError`
    (the first failure wins) and is not restarted.
    """

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        for attr, value in vars(cls).items():
            if attr in FRAMEWORK_ATTRIBUTES:
                what = f"the port {value!r}" if isinstance(value, _Port) else "an attribute"
                raise ActorDefinitionError(
                    f"{cls.__qualname__}.{attr} ({what}) shadows the framework's "
                    f"Actor.{attr} ({FRAMEWORK_ATTRIBUTES[attr]}); rename it (the bridge's "
                    f"/clock port is clock_out). Reserved: {', '.join(FRAMEWORK_ATTRIBUTES)}"
                )
            if attr in _HOOKS and isinstance(value, _Port):
                raise ActorDefinitionError(
                    f"{cls.__qualname__}.{attr} is the port {value!r}, but Actor.{attr} is "
                    f"a lifecycle hook the System calls; rename the port (hooks: "
                    f"{', '.join(sorted(_HOOKS))})"
                )

    def __init__(
        self,
        name: str | None = None,
        *,
        remap: Mapping[str, str] | None = None,
        params: Any = None,
    ) -> None:
        """``name`` (default: the class's, in snake_case), ``remap`` (topic renames, from
        -> to) and ``params``, kept as ``self.params``; when none are given, a ``Params``
        model whose fields all have defaults gives ``Params()``. A node with parameters
        needs no ``__init__`` of its own unless it has state to set up (ADR 0071)."""
        self.name = name or _snake(type(self).__name__)
        self._otonav_remap: dict[str, str] = dict(remap or {})
        self._otonav_ports: dict[str, Any] = {}
        self._otonav_clock: Clock | None = None
        self._otonav_params: Mapping[str, Any] = {}
        self._otonav_log = NodeLogger(self)
        model = getattr(type(self), "Params", None)
        if (
            params is None
            and isinstance(model, type)
            and issubclass(model, BaseModel)
            and not any(field.is_required() for field in model.model_fields.values())
        ):
            params = model()
        if params is not None:
            # Not declared on Actor: a subclass's own ``self.params: NavParams`` keeps
            # its type; a user's node annotates ``params: Params`` for mypy.
            setattr(self, "params", params)  # noqa: B010

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
    def log(self) -> NodeLogger:
        """The actor's logger, as rclpy's ``get_logger()``: ``self.log.info("...")``
        publishes ``/rosout`` in sim time and reaches the console (ADR 0070)."""
        return self._otonav_log

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
        """Called once before ``run``, and again before each restart, on the same
        instance: reset here what a restarted run must not inherit from the crashed one."""

    async def run(self) -> None:
        """The actor's body. The default does nothing (a purely passive actor)."""

    async def on_failure(self, exc: Exception) -> None:
        """Called when ``on_start`` or ``run`` raised ``exc``, after the crash is reported
        and before supervision decides (restart, or stop the system), shielded from
        cancellation. The ports still work: publish a last status, release a device.
        ``on_stop`` follows either way. If this raises, that is reported as a crash too
        and the actor is not restarted."""

    async def on_stop(self) -> None:
        """Called when the actor stops, however it stops (shielded from cancellation).
        If it raises, that is a crash: the system stops and its verdict names it."""


#: The lifecycle hooks: subclasses override them with methods; a port may not take their
#: names (the System would call the mailbox).
_HOOKS: Final = frozenset(
    attr
    for attr, value in vars(Actor).items()
    if not attr.startswith("_") and attr not in FRAMEWORK_ATTRIBUTES and callable(value)
)


def check_wirable(actor: Actor) -> None:
    """Raise :class:`ActorDefinitionError` if wiring ``actor`` would overwrite one of its
    own attributes (a port's name), or an instance attribute hides a framework name, or
    its ``__init__`` skipped ``Actor.__init__``. The System calls this before wiring."""
    cls = type(actor).__qualname__
    own = vars(actor)
    if "_otonav_ports" not in own:
        raise ActorDefinitionError(
            f"{cls}.__init__ did not call super().__init__(): the actor has no name, ports "
            "or clock yet; call super().__init__(name, remap=remap) first in __init__"
        )
    for attr in FRAMEWORK_ATTRIBUTES.keys() - {"name"}:
        if attr in own:
            raise ActorDefinitionError(
                f"actor '{actor.name}': the instance attribute {cls}.{attr} hides the "
                f"framework's Actor.{attr} ({FRAMEWORK_ATTRIBUTES[attr]}); rename it"
            )
    bound = actor._otonav_ports
    for port in type(actor).ports():
        if port.name in own and (port.name not in bound or own[port.name] is not bound[port.name]):
            raise ActorDefinitionError(
                f"actor '{actor.name}': {cls}.{port.name} is the port {port!r} and also an "
                f"instance attribute ({type(own[port.name]).__name__}) that wiring would "
                "overwrite with the port's mailbox; rename one of them"
            )
