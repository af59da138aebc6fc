"""What both time modes do with the world, written once: step its
:class:`~otonav.runtime._timesource.TimeSource` by whole ticks, freeze it when it raises
(time runs on so the run can stop and finish its recording), and evaluate the watchers
(sim-time predicates) in registration order.

The virtual-time loop steps when it is idle and runs the watchers before time moves on;
the real-time clock steps to follow the wall clock and runs them after each step. Each
reports a failure its own way (``on_failure``): the loop cancels the run, the clock tells
its system.
"""

from __future__ import annotations

from collections.abc import Callable

from otonav.runtime._errors import TimeSourceError
from otonav.runtime._timesource import FrozenSource, TimeSource, tick_rate

Watcher = Callable[[], bool]


class Stepper:
    """The world's source, the ticks stepped since it was attached, and the watchers."""

    __slots__ = ("_on_failure", "rate", "source", "ticks", "watchers")

    def __init__(self, source: TimeSource, on_failure: Callable[[BaseException], None]) -> None:
        self.source = source
        self.rate = tick_rate(source.tick)
        self.ticks = 0
        self.watchers: list[Watcher] = []
        self._on_failure = on_failure

    def attach(self, source: TimeSource) -> None:
        """Step ``source`` from now on, counting its ticks from 0."""
        self.source = source
        self.rate = tick_rate(source.tick)
        self.ticks = 0

    def step_to(self, ticks: int, now: float) -> None:
        """Advance the source to ``ticks``. If it raises (``now``: the sim time it was
        at), the world is frozen (a :class:`FrozenSource` from here on), time still
        moves, and ``on_failure`` gets a :class:`TimeSourceError`."""
        try:
            self.source.advance(ticks - self.ticks)
        except Exception as exc:
            # Not the fault of whoever asked for the time: freeze the world and report.
            error = TimeSourceError(now, exc)
            error.__cause__ = exc
            self.source = FrozenSource(self.source)
            self.source.advance(ticks - self.ticks)
            self.ticks = ticks
            self._on_failure(error)
        self.ticks = ticks

    def watch(self, watcher: Watcher) -> Callable[[], None]:
        """Evaluate ``watcher()`` at each :meth:`run_watchers` until it returns True.
        Returns a function that stops watching."""
        self.watchers.append(watcher)

        def remove() -> None:
            if watcher in self.watchers:
                self.watchers.remove(watcher)

        return remove

    def run_watchers(self) -> None:
        """Each watcher once, in registration order (a snapshot: a watcher may add or
        remove others); one that raises fails the run (``on_failure``) and is dropped."""
        for watcher in tuple(self.watchers):
            try:
                done = watcher()
            except Exception as exc:
                done = True
                self._on_failure(exc)
            if done and watcher in self.watchers:
                self.watchers.remove(watcher)
