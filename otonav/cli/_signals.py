"""Ctrl-C and SIGTERM during ``otonav run``: the first one stops the run, every later
one is ignored until the recording and the plot are finished.

Python's default (a KeyboardInterrupt wherever the main thread happens to be) and
asyncio's (a second Ctrl-C raises inside the loop, SIGTERM is restored to "kill" once
the loop closes) both let a second signal cut the shutdown short: a traceback, an
unindexed recording, no plot (issue 17). Here, while :class:`StopOnSignals` is active:

- before the run is armed (loading configs): SIGINT/SIGTERM raise KeyboardInterrupt,
  there is nothing to finish yet;
- once armed: the first signal cancels the run's task (on its loop, thread-safely), so
  every ``finally`` of the run executes, in order; if the task has not started yet it
  is cancelled as it starts; if it has already finished, the shutdown simply goes on;
- every further signal prints one note and is ignored (SIGKILL still kills);
- an actor that computes without yielding never lets the cancellation run: the loop's
  watchdog thread interrupts it after the loop's ``hold_grace`` (issue 27).

asyncio.Runner and ``run_task`` install their own handlers only over the defaults, so
they leave these in place.
"""

from __future__ import annotations

import asyncio
import signal
import sys
import threading
from types import FrameType, TracebackType
from typing import Any

EXIT_CODES = {signal.SIGINT: 130, signal.SIGTERM: 143}
_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class StopOnSignals:
    """Context manager; pass :meth:`attach` as the run's ``on_start``."""

    def __init__(self, finishing: str = "the recording and the plot") -> None:
        self.finishing = finishing
        """What a further signal is told is still being finished."""
        self.received: signal.Signals | None = None
        self._armed = False
        self._noted = False
        self._target: tuple[asyncio.AbstractEventLoop, asyncio.Task[Any]] | None = None
        self._previous: dict[signal.Signals, Any] = {}

    def __enter__(self) -> StopOnSignals:
        if threading.current_thread() is threading.main_thread():
            for sig in _SIGNALS:
                self._previous[sig] = signal.signal(sig, self._handle)
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        for sig, previous in self._previous.items():
            signal.signal(sig, previous)

    def arm(self) -> None:
        """From now on a signal stops the run instead of raising."""
        self._armed = True

    def disarm(self) -> None:
        """The run is over: from now on a first signal raises KeyboardInterrupt again (what
        follows is abandoned whole); one that came meanwhile raises it now."""
        self._armed, self._target = False, None
        if self.received is not None:
            raise KeyboardInterrupt

    def attach(self, loop: asyncio.AbstractEventLoop, task: asyncio.Task[Any]) -> None:
        """The run's ``on_start``: its loop and task, to cancel on the first signal."""
        self._target = (loop, task)
        if self.received is not None:
            task.cancel()  # the signal came while the run was being set up

    def _handle(self, signum: int, _frame: FrameType | None) -> None:
        sig = signal.Signals(signum)
        if self.received is None:
            self.received = sig
            if not self._armed:
                raise KeyboardInterrupt
            if self._target is not None:
                loop, task = self._target
                if not task.done() and not loop.is_closed():
                    loop.call_soon_threadsafe(task.cancel)
                    # An actor computing without yielding never lets that callback run:
                    # the loop's watchdog interrupts it (issue 27).
                    expect_progress = getattr(loop, "expect_progress", None)
                    if expect_progress is not None:
                        expect_progress(sig.name)
            return
        if not self._noted:
            self._noted = True
            print(
                f"otonav: {sig.name} again: still finishing {self.finishing} "
                "(SIGKILL would lose the end of the recording)",
                file=sys.stderr,
                flush=True,
            )

    def report(self) -> int:
        """One line on how the run ended, and its exit code (130 or 143)."""
        sig = self.received or signal.SIGINT
        what = "interrupted" if sig is signal.SIGINT else "terminated"
        held = getattr(self._target[0], "held_by", None) if self._target else None
        stopped = f" ({held} held the loop and was interrupted)" if held else ""
        print(
            f"otonav: {what}{stopped}; the recording and the plot were finished; "
            "no summary written",
            file=sys.stderr,
        )
        return EXIT_CODES[sig]
