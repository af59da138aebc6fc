"""A system: actors wired onto one bus, run under supervision in one task group.

    async with System([bridge, base, nav]) as system:
        await until(lambda: ..., within=20.0)

Wiring happens in the constructor, so every type and QoS error surfaces before anything
runs. Actors run under structured concurrency: an actor that raises is reported with
its name and traceback; by default the whole system then stops cleanly (every
``on_stop`` runs) and :class:`ActorCrashedError` is raised; a :class:`RestartPolicy`
restarts it instead, up to a cap within a sim-time window.
"""

from __future__ import annotations

import asyncio
import contextlib
import contextvars
import logging
import traceback
from collections.abc import Callable, Coroutine, Mapping, Sequence
from dataclasses import dataclass, field
from types import TracebackType
from typing import Any

import anyio
from anyio.abc import TaskGroup

from otonav.runtime._actor import Actor, check_wirable
from otonav.runtime._clock import (
    Clock,
    VirtualClock,
    reset_current_clock,
    set_current_clock,
)
from otonav.runtime._errors import ActorCrashedError, OtonavRuntimeError, WiringError
from otonav.runtime._events import ActorStatus, EventKind, SystemEvent
from otonav.runtime._graph import Graph, build_graph
from otonav.runtime._loop import VirtualTimeLoop
from otonav.runtime._mailbox import Bus, Endpoint, Publisher, Subscription
from otonav.runtime._qos import DEFAULT_QOS, QoS

log = logging.getLogger("otonav.runtime")


@dataclass(frozen=True, slots=True)
class RestartPolicy:
    """Restart a crashed actor, at most ``max_restarts`` times within ``window`` seconds
    of sim time; one more crash inside the window stops the system."""

    max_restarts: int = 3
    window: float = 10.0

    def __post_init__(self) -> None:
        if self.max_restarts < 0 or not self.window > 0:
            raise ValueError(
                f"RestartPolicy needs max_restarts >= 0 and window > 0 s, got "
                f"max_restarts={self.max_restarts}, window={self.window}"
            )


@dataclass(slots=True)
class _ActorState:
    actor: Actor
    policy: RestartPolicy | None
    restarts: int = 0
    crash_times: list[float] = field(default_factory=list)
    status: ActorStatus = ActorStatus.CREATED
    scope: anyio.CancelScope | None = None
    stop_requested: bool = False
    done: anyio.Event | None = None  # set when its supervisor has returned


_EXTERNAL = "external"
"""The endpoint name of code outside the actors (tests, hosts)."""


class System:
    """Actors on one bus; see the module docstring."""

    def __init__(
        self,
        actors: Sequence[Actor],
        *,
        clock: Clock | None = None,
        restart: RestartPolicy | Mapping[str, RestartPolicy] | None = None,
        bus: Bus | None = None,
    ) -> None:
        self.bus = bus or Bus()
        self._clock = clock
        self._states: dict[str, _ActorState] = {}
        self.events: list[SystemEvent] = []
        self._event_listeners: list[Callable[[SystemEvent], None]] = []
        self._running = 0  # supervisors still running; _all_done is set when none are
        self._all_done: anyio.Event | None = None
        self._failure: OtonavRuntimeError | None = None
        self._tg: TaskGroup | None = None
        self._stop_started = False
        self._stopped: anyio.Event | None = None
        self._clock_token: contextvars.Token[Clock] | None = None
        for actor in actors:
            check_wirable(actor)
            if actor.name in self._states:
                raise WiringError(
                    f"two actors are named '{actor.name}'; give each a unique name= "
                    "(names identify actors in the graph, logs and recordings)"
                )
            policy = restart.get(actor.name) if isinstance(restart, Mapping) else restart
            self._states[actor.name] = _ActorState(actor, policy)
        # Publishers first, so transient-local history and QoS checks see every pair
        # whatever the order of the actors.
        for direction in ("out", "in"):
            for state in self._states.values():
                self._wire(state.actor, direction)
        for state in self._states.values():
            state.actor.on_wired(self.bus)
        if clock is not None:
            clock.add_failure_listener(self._clock_failed)

    def _wire(self, actor: Actor, direction: str) -> None:
        for port in actor.ports():
            if port.direction != direction:
                continue
            topic = actor.topic_of(port)
            endpoint = Endpoint(actor.name, port.name)
            if direction == "out":
                bound: Any = self.bus.publisher(topic, port.msg_type, port.qos, endpoint=endpoint)
            else:
                bound = self.bus.subscribe(topic, port.msg_type, port.qos, endpoint=endpoint)
            actor._otonav_ports[port.name] = bound
            # The ports are non-data descriptors: the instance's own attribute wins, so
            # from now on ``self.odom`` is one dict lookup instead of two Python calls
            # (15 per 10 ms instant in the stack).
            vars(actor)[port.name] = bound

    # -- for code outside the actors (tests, hosts) -------------------------------------

    def subscribe(
        self, topic: str, msg_type: type[Any], qos: QoS = DEFAULT_QOS, *, name: str = _EXTERNAL
    ) -> Subscription[Any]:
        """A mailbox on ``topic`` for code outside the actors; same checks as ports."""
        return self.bus.subscribe(topic, msg_type, qos, endpoint=Endpoint(name, topic))

    def publisher(
        self, topic: str, msg_type: type[Any], qos: QoS = DEFAULT_QOS, *, name: str = _EXTERNAL
    ) -> Publisher[Any]:
        """A publisher on ``topic`` for code outside the actors; same checks as ports."""
        return self.bus.publisher(topic, msg_type, qos, endpoint=Endpoint(name, topic))

    def add_event_listener(self, listener: Callable[[SystemEvent], None]) -> None:
        """Call ``listener(event)`` for every lifecycle event (started, crashed, ...)."""
        self._event_listeners.append(listener)

    @property
    def clock(self) -> Clock:
        if self._clock is None:
            loop = asyncio.get_running_loop()
            if not isinstance(loop, VirtualTimeLoop):
                raise RuntimeError(
                    "System on a stock event loop needs clock=RealTimeClock(world) "
                    "(real-time mode); on a VirtualTimeLoop the loop is the clock"
                )
            self._clock = VirtualClock(loop)
        return self._clock

    def actor(self, name: str) -> Actor:
        return self._states[name].actor

    def graph(self) -> Graph:
        """Actors, ports, topics, types, QoS and live statistics, as plain data."""
        return build_graph(
            self.bus,
            {
                name: (type(s.actor).__name__, s.status, s.restarts)
                for name, s in self._states.items()
            },
        )

    # -- running ------------------------------------------------------------------------

    def _event(self, actor: str, kind: EventKind, detail: str = "") -> None:
        now = self._clock.now() if self._clock is not None else 0.0
        event = SystemEvent(now, actor, kind, detail)
        self.events.append(event)
        for listener in self._event_listeners:
            listener(event)
        log.log(
            logging.ERROR if kind is EventKind.CRASHED else logging.INFO,
            "[%.3f] %s %s %s",
            now,
            actor,
            kind,
            detail,
        )

    def _give_clocks(self) -> None:
        # Every actor has its clock before any starts: on_start hooks publish, and a
        # recorder stamps what it receives with its clock.
        for state in self._states.values():
            state.actor._otonav_clock = self.clock

    async def _supervise(self, state: _ActorState) -> None:
        state.scope = anyio.CancelScope()
        try:
            if not state.stop_requested:  # stopped before it ever started: nothing to do
                with state.scope:
                    await self._supervise_in_scope(state)
        finally:
            assert state.done is not None
            state.done.set()
            self._running -= 1
            if not self._running and self._all_done is not None:
                self._all_done.set()

    async def _supervise_in_scope(self, state: _ActorState) -> None:
        """One actor's life: ``on_start``, ``run``; on a crash ``on_failure``, then the
        policy (restart: ``on_stop`` and round again on the same instance; else stop
        the system); ``on_stop`` once for every ``on_start`` that returned or raised (one
        cancelled by a stop has nothing to stop)."""
        actor = state.actor
        stop_due = False
        try:
            while not state.stop_requested:
                try:
                    await actor.on_start()
                    stop_due = True
                    state.status = ActorStatus.RUNNING
                    self._event(actor.name, EventKind.STARTED)
                    await _unrequested_cancel_is_a_crash(actor.run())
                    state.status = ActorStatus.FINISHED
                    self._event(actor.name, EventKind.FINISHED)
                    return
                except Exception as exc:
                    stop_due = True
                    text = _format(exc)
                    now = self.clock.now()
                    self._event(actor.name, EventKind.CRASHED, text)
                    hook_error = await self._on_failure(actor, exc)
                    if hook_error is None and self._may_restart(state, now):
                        state.restarts += 1
                        self._event(actor.name, EventKind.RESTARTED, f"restart {state.restarts}")
                        stop_due = False
                        if not await self._stop_actor(state):
                            return  # on_stop raised: reported as a crash, the system stops
                        continue
                    if hook_error is not None:
                        text += f"\nand then in on_failure: {hook_error}"
                    state.status = ActorStatus.CRASHED
                    self._fail(actor.name, now, text, exc)
                    return
        finally:
            if stop_due:
                await self._stop_actor(state)

    async def _on_failure(self, actor: Actor, exc: Exception) -> str | None:
        """Call ``actor.on_failure(exc)`` (shielded, like ``on_stop``); if it raises,
        report that as a crash and return its traceback (the actor is then not
        restarted: its own clean-up is broken)."""
        with anyio.CancelScope(shield=True):
            try:
                await actor.on_failure(exc)
            except Exception as hook_exc:
                text = _format(hook_exc)
                self._event(actor.name, EventKind.CRASHED, "in on_failure: " + text)
                return text
        return None

    def _fail(self, actor: str, now: float, text: str, exc: BaseException) -> None:
        """Stop the system because ``actor`` crashed; the first failure is the verdict."""
        if self._failure is None:
            self._failure = ActorCrashedError(actor, now, text)
            self._failure.__cause__ = exc
        self.stop()

    def _clock_failed(self, error: BaseException) -> None:
        """The real-time clock's world (or a watcher) raised inside someone's ``now()``:
        stop the system with it rather than crash the actor that asked for the time."""
        text = _format(error)
        self._event("clock", EventKind.CRASHED, text)
        if self._failure is None:
            if isinstance(error, OtonavRuntimeError):
                self._failure = error
            else:
                self._failure = ActorCrashedError("clock (a sim-time watcher)", 0.0, text)
                self._failure.__cause__ = error
        self.stop()

    def _may_restart(self, state: _ActorState, now: float) -> bool:
        policy = state.policy
        if policy is None:
            return False
        state.crash_times = [t for t in state.crash_times if t > now - policy.window]
        state.crash_times.append(now)
        return len(state.crash_times) <= policy.max_restarts

    async def _stop_actor(self, state: _ActorState) -> bool:
        """Run ``on_stop`` (shielded). If it raises, that is a crash like any other: it is
        reported, the actor's status is crashed and the system stops with
        :class:`ActorCrashedError` (unless an earlier failure already is the verdict).
        Returns whether ``on_stop`` returned normally."""
        ok = True
        with anyio.CancelScope(shield=True):
            try:
                await state.actor.on_stop()
            except Exception as exc:
                ok = False
                text = "in on_stop: " + _format(exc)
                self._event(state.actor.name, EventKind.CRASHED, text)
                state.status = ActorStatus.CRASHED
                self._fail(state.actor.name, self.clock.now(), text, exc)
        if state.status is ActorStatus.RUNNING:
            state.status = ActorStatus.STOPPED
        self._event(state.actor.name, EventKind.STOPPED)
        return ok

    async def __aenter__(self) -> System:
        self._clock_token = set_current_clock(self.clock)
        self._give_clocks()
        self._all_done = anyio.Event()
        self._stopped = anyio.Event()
        self._stop_started = False
        for state in self._states.values():
            state.done = anyio.Event()
            state.stop_requested = False
        self._running = len(self._states)
        if not self._running:
            self._all_done.set()
        self._tg = anyio.create_task_group()
        await self._tg.__aenter__()
        for state in self._states.values():
            self._tg.start_soon(self._supervise, state, name=f"actor:{state.actor.name}")
        return self

    async def __aexit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> bool:
        assert self._tg is not None
        assert self._stopped is not None
        self._stop_started = True
        if not self._stopped.is_set():
            # Here, not in a task: a task started in a cancelled group may never run.
            # (If a crash already started the stopper, both wait on the same events.)
            await self._stop_in_order()
        try:
            suppressed = await self._tg.__aexit__(exc_type, exc, tb)
        except BaseExceptionGroup as group:
            # anyio wraps the body's own exception in a group: give the caller the
            # exception it raised (a test sees its SimTimeoutError, not a group) --
            # unless an actor crashed too: that is the cause, and it is raised.
            if exc is not None and group.exceptions == (exc,):
                failure, self._failure = self._failure, None
                if failure is not None:
                    raise failure from exc
                raise exc from None
            raise
        finally:
            self._tg = None
            _reset_clock(self._clock_token)
        failure, self._failure = self._failure, None
        if failure is not None:
            raise failure
        return bool(suppressed)

    def stop(self) -> None:
        """Stop every actor (each ``on_stop`` runs); ``run()`` then returns.

        Actors stop one after another in reverse start order, like a launch file
        shutting down: each is cancelled only once the one after it has finished its
        ``on_stop``, so the first actor (the recorder) stops last and sees everything the
        others published while stopping. Only then is the task group (and the body of
        the ``async with``) cancelled. (anyio cancels a group's tasks in set order,
        memory addresses, which made two identical runs log their stops in different
        orders; cancelling all scopes at once let a recorder drain before the others'
        last messages.)
        """
        if self._tg is None or self._stop_started:
            return
        self._stop_started = True
        self._tg.start_soon(self._stop_in_order, name="otonav-stop")

    async def _stop_in_order(self) -> None:
        with anyio.CancelScope(shield=True):
            for state in reversed(self._states.values()):
                state.stop_requested = True
                if state.scope is not None:
                    state.scope.cancel()
                assert state.done is not None
                await state.done.wait()
        assert self._stopped is not None
        self._stopped.set()
        if self._tg is not None:
            self._tg.cancel_scope.cancel()

    async def wait_finished(self) -> None:
        """Inside ``async with system``: wait until every actor's ``run`` returned or
        the system was stopped (:meth:`stop`, a crash)."""
        if self._all_done is None:
            raise RuntimeError("wait_finished() is for a running system (async with system)")
        await self._all_done.wait()

    async def run(self) -> None:
        """Run until every actor's ``run`` returned, :meth:`stop` is called, or a crash."""
        async with self:
            await self.wait_finished()


class UnrequestedCancelError(RuntimeError):
    """An actor raised ``CancelledError`` although nothing cancelled it: a crash (it
    used to end the run silently, logged as "stopped"; issue 27)."""


async def _unrequested_cancel_is_a_crash(body: Coroutine[Any, Any, None]) -> None:
    """Await ``body``; a ``CancelledError`` the task was not asked for (no ``cancel()``
    pending: ``cancelling() == 0``, which anyio's scopes and asyncio both set) becomes
    :class:`UnrequestedCancelError`, handled like any crash."""
    try:
        await body
    except asyncio.CancelledError as exc:
        task = asyncio.current_task()
        if task is None or task.cancelling():
            raise
        raise UnrequestedCancelError(
            f"run() raised CancelledError ({exc or 'no message'}) but nothing cancelled "
            "it; an actor that wants to end returns from run()"
        ) from exc


def _format(exc: BaseException) -> str:
    return "".join(traceback.format_exception(exc))


def _reset_clock(token: contextvars.Token[Clock] | None) -> None:
    if token is not None:
        # ValueError: exited in another context (e.g. a different task).
        with contextlib.suppress(ValueError):
            reset_current_clock(token)
