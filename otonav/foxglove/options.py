"""The live view's settings and its one-line error: what every part of otonav.foxglove
reads, importable without the ``otonav[foxglove]`` extra."""

from __future__ import annotations

import math
from dataclasses import dataclass

from otonav.actors import topics

DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 8765


class LiveViewError(ValueError):
    """The live view cannot start: one line saying why and what to do."""


@dataclass(frozen=True, slots=True)
class LiveViewOptions:
    """Where to serve and how much to buffer."""

    host: str = DEFAULT_HOST
    """Interface to bind: loopback unless asked (``0.0.0.0`` serves every interface)."""
    port: int = DEFAULT_PORT
    """TCP port (Foxglove's convention, 8765); 0 picks a free one."""
    backlog: int = 256
    """Messages the server queues per client before dropping its oldest."""
    depth: int = 64
    """Messages each topic's tap keeps between two flushes before dropping its oldest."""
    period: float = 0.02
    """Seconds of sim time between flushes (50 Hz at 1x)."""
    wait_for_subscriber: float | None = None
    """Hold sim time at the start until a client subscribes, for at most this many
    wall seconds (None: do not wait). Sim time does not move while it waits."""
    wait_for_subscriptions: int = 1
    """With ``wait_for_subscriber``: how many channel subscriptions to wait for."""
    client_publish: tuple[str, ...] = (topics.GOAL,)
    """Topics clients may publish on (``clientPublish``); empty: clients only watch."""

    def __post_init__(self) -> None:
        if not 0 <= self.port <= 65535:
            raise LiveViewError(f"foxglove port {self.port}: must be 0..65535 (0: any free)")
        if self.backlog < 1 or self.depth < 1:
            raise LiveViewError("foxglove backlog and depth must be >= 1 message")
        if not (self.period > 0 and math.isfinite(self.period)):
            raise LiveViewError(f"foxglove period {self.period}: must be > 0 s of sim time")
        wait = self.wait_for_subscriber
        if wait is not None and not (wait > 0 and math.isfinite(wait)):
            raise LiveViewError(f"--foxglove-wait {wait}: must be a number of seconds > 0")
