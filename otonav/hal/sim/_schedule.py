"""Faults on a timetable: every fault the drive emulator can inject, each with a start
(and, where it can end, an end) in seconds of sim time, so that a config file, the CLI
(``--set hal.sim.faults...``) and a sweep can ask for them, not only Python.

The drive emulator applies its plan at each exchange (every encoder period, 10 ms by
default): a fault starts or ends at the first exchange at or after its time.
"""

from __future__ import annotations

from dataclasses import dataclass

from otonav.hal.can._protocol import AxisError

__all__ = ["BusFaults", "FaultPlan", "Window"]


@dataclass(slots=True)
class BusFaults:
    """Bus-level fault injection, applied to frames in both directions.

    ``drop_rate``: probability (0..1) that a frame is lost. ``delay``: seconds every
    frame is held back, plus up to ``jitter`` seconds more (uniform; frames may then
    arrive out of order, as behind a congested gateway). ``dropped``: frames lost so far.
    """

    drop_rate: float = 0.0
    delay: float = 0.0
    jitter: float = 0.0
    dropped: int = 0

    @property
    def lossy(self) -> bool:
        return self.drop_rate > 0.0 or self.delay > 0.0 or self.jitter > 0.0


@dataclass(frozen=True, slots=True)
class Window:
    """From ``start`` to ``end`` (None: to the end of the run), s of sim time."""

    start: float
    end: float | None = None

    def holds(self, t: float) -> bool:
        return self.start <= t and (self.end is None or t < self.end)


@dataclass(frozen=True, slots=True)
class FaultPlan:
    """What to inject and when. A field left at its default injects nothing."""

    drop_rate: float = 0.0
    """Probability (0..1) that a frame is lost, during ``drop``."""
    drop: Window = Window(0.0)
    delay: float = 0.0
    """s every frame is held back (plus up to ``jitter`` s), during ``delayed``."""
    jitter: float = 0.0
    delayed: Window = Window(0.0)
    axis_error_node: int | None = None
    """The drive that reports ``axis_error_code`` and disarms at ``axis_error_at``."""
    axis_error_code: int = int(AxisError.DRV_FAULT)
    axis_error_at: float = 0.0
    bus_off: Window | None = None
    """The bus is off (nothing passes) during this window."""
    heartbeat_node: int | None = None
    """The drive whose heartbeat stops during ``heartbeat_lost``."""
    heartbeat_lost: Window = Window(0.0)

    @property
    def empty(self) -> bool:
        return (
            self.drop_rate == 0.0
            and self.delay == 0.0
            and self.jitter == 0.0
            and self.axis_error_node is None
            and self.bus_off is None
            and self.heartbeat_node is None
        )

    def times(self) -> list[float]:
        """Every instant at which something starts or ends."""
        windows = [self.drop, self.delayed, self.heartbeat_lost]
        if self.bus_off is not None:
            windows.append(self.bus_off)
        edges = [w.start for w in windows] + [w.end for w in windows if w.end is not None]
        if self.axis_error_node is not None:
            edges.append(self.axis_error_at)
        return sorted(set(edges))
