"""The actor runtime: generic, no robot, no MuJoCo.

- ``loop``: the virtual-time asyncio loop (sim time is loop time) and ``run_blocking``;
  ``watchdog``: its wall-clock ceiling and stop requests, enforced from a thread.
- ``timesource``: what advances time (a physics world, or ``JumpSource``).
- ``clock``: sim time for actors, one contract (``Clock``) and its two modes
  (``VirtualClock``, ``RealTimeClock``, capped at ``MAX_STEP_BATCH`` per advance); ``Rate``;
  ``timemode``: the mode a run is asked for, as a value (``Virtual()``, ``RealTime(scale)``).
- ``qos`` / ``mailbox``: QoS with ROS 2 matching, typed topics, publishers, mailboxes.
- ``actor`` / ``system``: actors with typed ports, wired and supervised by a ``System``;
  ``events``: what the system reports about them (``SystemEvent``, ``EventKind``).
- ``waits``: ``until`` and ``next_message``, awaitables on sim time.
- ``graph``: the wiring and statistics as data.
"""

from otonav.runtime._actor import Actor, Input, Output
from otonav.runtime._clock import (
    MAX_STEP_BATCH,
    Clock,
    Rate,
    RealTimeClock,
    VirtualClock,
    current_clock,
)
from otonav.runtime._errors import (
    ActorCrashedError,
    ActorDefinitionError,
    DeadlockError,
    LoopHeldError,
    OtonavRuntimeError,
    QoSIncompatibleError,
    SimTimeoutError,
    TimeSourceError,
    TopicTypeError,
    WallClockCeilingError,
    WiringError,
)
from otonav.runtime._events import ActorStatus, EventKind, SystemEvent
from otonav.runtime._graph import Graph
from otonav.runtime._loop import VirtualTimeLoop, run_blocking, virtual_loop_factory
from otonav.runtime._mailbox import Bus, Endpoint, MailboxStatistics, Publisher, Subscription
from otonav.runtime._qos import (
    DEFAULT_QOS,
    LATCHED_QOS,
    SENSOR_DATA_QOS,
    Durability,
    QoS,
    Reliability,
)
from otonav.runtime._system import RestartPolicy, System
from otonav.runtime._timemode import RealTime, TimeMode, Virtual
from otonav.runtime._timesource import JumpSource, TimeSource
from otonav.runtime._waits import next_message, until

__all__ = (
    "DEFAULT_QOS",
    "LATCHED_QOS",
    "MAX_STEP_BATCH",
    "SENSOR_DATA_QOS",
    "Actor",
    "ActorCrashedError",
    "ActorDefinitionError",
    "ActorStatus",
    "Bus",
    "Clock",
    "DeadlockError",
    "Durability",
    "Endpoint",
    "EventKind",
    "Graph",
    "Input",
    "JumpSource",
    "LoopHeldError",
    "MailboxStatistics",
    "OtonavRuntimeError",
    "Output",
    "Publisher",
    "QoS",
    "QoSIncompatibleError",
    "Rate",
    "RealTime",
    "RealTimeClock",
    "Reliability",
    "RestartPolicy",
    "SimTimeoutError",
    "Subscription",
    "System",
    "SystemEvent",
    "TimeMode",
    "TimeSource",
    "TimeSourceError",
    "TopicTypeError",
    "Virtual",
    "VirtualClock",
    "VirtualTimeLoop",
    "WallClockCeilingError",
    "WiringError",
    "current_clock",
    "next_message",
    "run_blocking",
    "until",
    "virtual_loop_factory",
)
