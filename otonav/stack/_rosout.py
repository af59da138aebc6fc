"""/rosout: the system's lifecycle events (started, crashed, restarted, stopped) and
every actor's ``self.log`` lines as ``rcl_interfaces/msg/Log``, so a recording carries
them next to the data (ADR 0070)."""

from __future__ import annotations

import contextlib

import anyio

from otonav.actors import _topics as topics
from otonav.actors._topics import ROSOUT_QOS
from otonav.msgs import Log, Time
from otonav.runtime import EventKind, System, SystemEvent

__all__ = ["ROSOUT_QOS", "attach_rosout"]

_LEVELS = {EventKind.CRASHED: Log.ERROR, EventKind.RESTARTED: Log.WARN}


def attach_rosout(system: System) -> None:
    """Publish every event of ``system`` and every line its actors log on /rosout
    (dropped, not blocking, when full)."""
    publisher = system.publisher(topics.ROSOUT, Log, ROSOUT_QOS, name="rosout")

    def log_line(
        now: float, level: int, name: str, text: str, file: str, function: str, line: int
    ) -> None:
        message = Log.fast(
            stamp=Time.from_seconds(now),
            level=level,
            name=name,
            msg=text,
            file=file,
            function=function,
            line=line,
        )
        with contextlib.suppress(anyio.WouldBlock):
            publisher.publish_nowait(message)

    for node in system.graph().actors:
        system.actor(node.name).log.sink = log_line

    def publish(event: SystemEvent) -> None:
        text = str(event.kind) if not event.detail else f"{event.kind}: {event.detail}"
        level = _LEVELS.get(event.kind, Log.INFO)
        log_line(event.sim_time, level, event.actor, text, "", "", 0)

    system.add_event_listener(publish)
