"""Errors of the actor runtime. Each message names the parts involved and the fix."""

from __future__ import annotations

from otonav.errors import OtonavError, UsageError


class OtonavRuntimeError(OtonavError):
    """Base class of every error the runtime raises on purpose."""


class WiringError(OtonavRuntimeError, UsageError):
    """Ports, topics or QoS that cannot be connected; raised at wiring time, never later.
    A user's mistake in the graph they launched, so a :class:`~otonav.errors.UsageError`:
    the CLI prints its one line and exits 2 (issue 39)."""


class ActorDefinitionError(WiringError, TypeError):
    """An actor that shadows a name of the framework (a port or attribute called
    ``clock``, a port called ``run``, an attribute a port would overwrite): raised when
    the class is defined, or when the instance is wired, naming the attribute and the
    class."""


class TopicTypeError(WiringError, TypeError):
    """A port or a message whose type differs from its topic's type."""


class QoSIncompatibleError(WiringError):
    """A publisher and a subscriber whose QoS ROS 2 would refuse to match."""


class ActorCrashedError(OtonavRuntimeError):
    """An actor raised and the supervision policy stopped the system.

    The original exception is the ``__cause__``; ``actor`` names the actor and
    ``traceback_text`` holds the formatted traceback as it was reported.
    """

    def __init__(self, actor: str, sim_time: float, traceback_text: str) -> None:
        super().__init__(
            f"actor '{actor}' crashed at sim time {sim_time:.3f} s and the system was stopped "
            f"(policy: stop); its traceback:\n{traceback_text}"
        )
        self.actor = actor
        self.sim_time = sim_time
        self.traceback_text = traceback_text


class SimTimeoutError(TimeoutError, OtonavRuntimeError):
    """A sim-time wait ran out of budget. Says the sim time, the budget and the last value."""

    def __init__(self, what: str, sim_time: float, budget: float, last: object) -> None:
        super().__init__(
            f"{what} not met within {budget:g} s of sim time "
            f"(gave up at sim time {sim_time:.3f} s; last observed: {last!r})"
        )
        self.what = what
        self.sim_time = sim_time
        self.budget = budget
        self.last = last


class TimeSourceError(OtonavRuntimeError):
    """The time source (the world) raised while being advanced. The original exception
    is the ``__cause__``. From then on the world is frozen: sim time runs on without
    stepping it, so the run can still shut down (every ``on_stop``, the recording)."""

    def __init__(self, sim_time: float, cause: BaseException) -> None:
        super().__init__(
            f"the time source's advance() raised at sim time {sim_time:.3f} s: {cause!r}; "
            "the world is frozen from here and the run was stopped"
        )
        self.sim_time = sim_time


class DeadlockError(OtonavRuntimeError):
    """The virtual-time loop had nothing that could ever wake it: no timer, no ready
    callback, no I/O, no thread running."""


class WallClockCeilingError(OtonavRuntimeError):
    """A run exceeded its wall-clock ceiling (a hang or livelock, not a slow sim)."""


class LoopHeldError(OtonavRuntimeError):
    """Raised inside a callback that held the virtual-time loop (computed without
    yielding) past the wall-clock ceiling or a stop request; the watchdog raises it
    from outside the loop (``otonav.runtime._watchdog``)."""
