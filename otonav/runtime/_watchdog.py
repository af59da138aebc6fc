"""A watchdog thread: the wall-clock ceiling and stop requests, enforced from outside.

The virtual-time loop checks its wall-clock ceiling in its own idle path and every 256
passes (``otonav.runtime._loop``). A callback that never yields (an actor computing in a
``while True``) never returns to either: it ran 698 s past an 8 s ceiling, and a SIGTERM,
whose cancellation is a callback too, was never handled (issue 27; a
callback that never yields holds every timer, the ceiling's too: ADR 0039). This thread
watches the loop instead:

- the loop counts its passes (``beats``) and says when it is waiting in its selector;
- once the ceiling has passed and the loop still passes, it is asked to check its ceiling
  at its next pass (a pass draining a flood can take 30 ms: 256 of them are 8 s);
- once the ceiling has passed, or a stop was asked for (:meth:`LoopWatchdog.expect_progress`:
  a signal, a host cancelling a run), a loop whose beat count has not moved for ``grace``
  wall seconds while not waiting is *held*;
- the watchdog then names what holds it (the current task, ``actor:NAME``, and the line
  it is at: ``loop.held_by``), fails the run with that past the ceiling
  (``loop.fail_threadsafe``; a stop request already has its cancellation) and raises
  :class:`~otonav.runtime._errors.LoopHeldError` inside the held callback
  (``PyThreadState_SetAsyncExc``), again every ``grace`` seconds while it stays held
  (an actor may swallow one). The actor then crashes like any other, the system stops
  cleanly and the recording is finished.

A callback blocked inside C code (a long numpy call, a syscall) is interrupted only when
it returns to Python bytecode. Costs: one thread per run, asleep until the ceiling (or
a stop request), then polling every 0.1 s; one integer increment per loop pass.
"""

from __future__ import annotations

import asyncio
import ctypes
import sys
import threading
import time
from pathlib import Path
from typing import Protocol

from otonav.runtime._errors import LoopHeldError, WallClockCeilingError


class WatchedLoop(Protocol):
    """What the watchdog watches: :class:`~otonav.runtime._loop.VirtualTimeLoop`."""

    beats: int
    waiting: bool
    held_by: str | None

    def time(self) -> float: ...

    def fail_threadsafe(self, error: BaseException) -> None: ...

    def check_ceiling_threadsafe(self) -> None: ...


POLL_S = 0.1
"""How often a due watchdog looks at the beat count."""


def _interrupt(thread_id: int) -> None:
    """Raise :class:`LoopHeldError` in ``thread_id`` at its next bytecode."""
    ctypes.pythonapi.PyThreadState_SetAsyncExc(
        ctypes.c_ulong(thread_id), ctypes.py_object(LoopHeldError)
    )


def describe_holder(loop: asyncio.AbstractEventLoop, thread_id: int) -> str:
    """What holds ``loop`` (run by ``thread_id``): ``actor 'nav' (at file.py:12 in run)``."""
    task = asyncio.current_task(loop)
    who = "a callback"
    if task is not None:
        name = task.get_name()
        who = f"actor '{name[6:]}'" if name.startswith("actor:") else f"task '{name}'"
    frame = sys._current_frames().get(thread_id)
    where = ""
    if frame is not None:
        code = frame.f_code
        where = f" (at {Path(code.co_filename).name}:{frame.f_lineno} in {code.co_name})"
    return who + where


class LoopWatchdog:
    """Watches ``loop`` run by the calling thread; see the module docstring."""

    def __init__(self, loop: WatchedLoop, ceiling: float | None, grace: float) -> None:
        self._loop = loop
        self._ceiling = ceiling
        self._grace = grace
        self._thread_id = threading.get_ident()
        self._start = time.monotonic()
        self._wake = threading.Event()
        self._done = False
        self._why: str | None = None  # a stop request: say it in the failure
        self._thread = threading.Thread(target=self._watch, name="otonav-watchdog", daemon=True)

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        self._done = True
        self._wake.set()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join()

    def expect_progress(self, why: str) -> None:
        """Thread- and signal-safe: a stop was asked for (``why``: "SIGTERM"); a loop
        that makes no progress from now on for ``grace`` seconds is interrupted."""
        if self._why is None:
            self._why = why
        self._wake.set()

    def _due(self, now: float) -> bool:
        return self._why is not None or (
            self._ceiling is not None and now - self._start > self._ceiling
        )

    def _watch(self) -> None:
        last_beats = -1
        still_since = 0.0
        while not self._done:
            now = time.monotonic()
            if not self._due(now):
                timeout = None
                if self._ceiling is not None:
                    timeout = max(POLL_S, self._start + self._ceiling - now + POLL_S)
                self._wake.wait(timeout)
                self._wake.clear()
                continue
            beats = self._loop.beats
            if beats != last_beats or self._loop.waiting:
                if self._why is None and last_beats >= 0:
                    self._check_ceiling()
                last_beats, still_since = beats, now
            elif now - still_since >= self._grace:
                self._held(now - still_since)
                still_since = now
            self._wake.wait(POLL_S)
            self._wake.clear()

    def _check_ceiling(self) -> None:
        """Past the ceiling, the loop still passing: have it check its ceiling at its
        next pass. Its own check runs every 256 passes, and a pass that drained a flood
        (an actor publishing in a tight loop) took 30 ms: the run went on 8 s past its
        ceiling, and as long again before its failure stopped the loop (issue 41)."""
        self._loop.check_ceiling_threadsafe()

    def _held(self, for_s: float) -> None:
        loop = self._loop
        assert isinstance(loop, asyncio.AbstractEventLoop)  # a VirtualTimeLoop
        holder = describe_holder(loop, self._thread_id)
        self._loop.held_by = holder
        held = f"{holder} held the loop (no pass for {for_s:.1f} s: it never yields)"
        if self._why is None:  # the ceiling: the run fails with it
            self._loop.fail_threadsafe(
                WallClockCeilingError(
                    f"run exceeded its wall-clock ceiling of {self._ceiling:g} s "
                    f"(sim time reached {self._loop.time():.3f} s): {held}"
                )
            )
        # A stop request: the requester's cancellation goes on once the callback is out.
        _interrupt(self._thread_id)
