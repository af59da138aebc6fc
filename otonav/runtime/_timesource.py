"""What moves time forward: the contract between the loop and the world.

The virtual-time loop never invents time: when nothing is ready it asks its time source
to advance a whole number of ticks. A physics world steps (``otonav.hal``); the
:class:`JumpSource` below just jumps, for runtime tests with no physics.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable


@runtime_checkable
class TimeSource(Protocol):
    """Anything that can advance the world by whole ticks.

    ``tick`` is the length of one tick in seconds (the physics step). ``advance(n)`` moves
    the world ``n`` ticks forward; nothing else may step it.
    """

    @property
    def tick(self) -> float: ...

    def advance(self, n: int) -> None: ...


class JumpSource:
    """A time source with no world: advancing costs nothing. 1 µs ticks by default."""

    __slots__ = ("_tick", "ticks")

    def __init__(self, tick: float = 1e-6) -> None:
        if not tick > 0:
            raise ValueError(f"JumpSource tick must be > 0 seconds, got {tick!r}")
        self._tick = tick
        self.ticks = 0

    @property
    def tick(self) -> float:
        return self._tick

    def advance(self, n: int) -> None:
        self.ticks += n


class FrozenSource(JumpSource):
    """Stands in for a time source whose ``advance()`` raised: time runs on with the
    same tick, the world (``failed``) is no longer stepped."""

    __slots__ = ("failed",)

    def __init__(self, failed: TimeSource) -> None:
        super().__init__(failed.tick)
        self.failed = failed


def tick_rate(tick: float) -> float:
    """Ticks per second, snapped to an integer when ``1 / tick`` is one (0.002 s -> 500).

    Time is then ``ticks / rate``: a correctly rounded division, so tick instants are
    the same doubles as the decimal literals people write (1100 / 500 == 2.2, whereas
    1100 * 0.002 == 2.2000000000000002).
    """
    rate = 1.0 / tick
    nearest = round(rate)
    return float(nearest) if nearest > 0 and abs(rate - nearest) < 1e-6 * rate else rate
