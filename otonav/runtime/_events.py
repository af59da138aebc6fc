"""What a :class:`~otonav.runtime._system.System` reports about its actors: lifecycle
events and statuses.

Both are :class:`~enum.StrEnum`: a member *is* its text, so ``event.kind == "crashed"``,
``f"{event.kind}"``, ``json.dumps`` and dict lookups by the text behave as they did when
these were plain strings, and what goes out (/rosout lines, logs, ``otonav graph``) is
byte for byte the same.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

__all__ = ["ActorStatus", "EventKind", "SystemEvent"]


class EventKind(StrEnum):
    """What happened to an actor (:attr:`SystemEvent.kind`)."""

    STARTED = "started"
    """``on_start`` returned; ``run`` begins."""
    FINISHED = "finished"
    """``run`` returned: the actor is done, the others go on."""
    CRASHED = "crashed"
    """``on_start``, ``run``, ``on_failure`` or ``on_stop`` raised (the detail says which,
    with the traceback)."""
    RESTARTED = "restarted"
    """The restart policy restarts the actor after a crash (detail: ``restart N``)."""
    STOPPED = "stopped"
    """``on_stop`` has run (or raised): the actor is stopped."""


class ActorStatus(StrEnum):
    """Where an actor is in its life (the graph's ``status``)."""

    CREATED = "created"
    RUNNING = "running"
    FINISHED = "finished"
    CRASHED = "crashed"
    STOPPED = "stopped"


@dataclass(frozen=True, slots=True)
class SystemEvent:
    """A lifecycle event of one actor, at a sim time."""

    sim_time: float
    """Sim time of the event, s."""
    actor: str
    """The actor's name (``"clock"`` when the real-time clock's world failed)."""
    kind: EventKind
    """What happened."""
    detail: str = ""
    """The traceback of a crash, ``restart N`` for a restart, else empty."""
