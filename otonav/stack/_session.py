"""One run of the robot stack: its world, time mode, recording, and one teardown.

Every runner (a judged scenario, the engine's live stack, the benchmarks) hands a
:class:`StackSession` its world and actors; the session adds the recorder, wires the
:class:`~otonav.runtime.System`, puts the world in charge of time and tears everything
down the same way, whatever ends the run (ADR 0007):

1. the robot actors stop, one after another in reverse start order, each ``on_stop``
   finished before the next one is cancelled (``System.stop``);
2. the recorder, listed first, stops last: its ``on_stop`` drains the funnel;
3. a final drain once the system has exited picks up the last lines (the recorder's
   own "stopped" on /rosout); an ``epilogue`` may then append to the file (a verdict);
4. the writer is finished (an indexed file);
5. cleanups registered with :meth:`StackSession.add_cleanup` run (a viewer window),
   then the world (HAL) is closed;
6. in virtual time, the loop gets back the time source it had before: code running on
   the loop after the session (a test's next ``sleep``) does not step a closed world.

Each step runs even if an earlier one raised. Time mode (``time=``, ADR 0082):
:class:`~otonav.runtime.Virtual` (the default) makes the world the running
:class:`~otonav.runtime.VirtualTimeLoop`'s time source; :class:`~otonav.runtime.RealTime`
paces it to the wall clock on any loop, with a pacer task stepping it in small batches
while every actor sleeps.
"""

from __future__ import annotations

import asyncio
import contextlib
from collections.abc import AsyncIterator, Callable, Mapping, Sequence
from pathlib import Path

from otonav.actors._recorder import Recorder
from otonav.hal import RobotHardwareInterface
from otonav.record._writer import RecordingWriter
from otonav.runtime import (
    Actor,
    Clock,
    RealTime,
    RealTimeClock,
    RestartPolicy,
    System,
    TimeMode,
    TimeSource,
    Virtual,
)
from otonav.runtime._loop import VirtualTimeLoop
from otonav.stack._rosout import attach_rosout
from otonav.stack._worldmeta import WORLD_METADATA, world_metadata

__all__ = ("StackSession",)


class StackSession:
    """The world, the actors (after a recorder when ``record_to`` is set), the system
    and their teardown. The session owns ``hal`` from construction on: if building it
    fails, the world is closed.

    Use ``async with session.running() as system:`` (tears down on exit), or
    ``session.running(close=False)`` followed by :meth:`close` when something must be
    appended to the recording after the run (a scenario's verdict). Time as in the
    module docstring; in real time the session's clock is :attr:`realtime_clock`.
    """

    def __init__(
        self,
        hal: RobotHardwareInterface,
        actors: Sequence[Actor],
        *,
        time: TimeMode = Virtual(),
        record_to: Path | RecordingWriter | None = None,
        restart: RestartPolicy | Mapping[str, RestartPolicy] | None = None,
    ) -> None:
        self.hal = hal
        self.writer: RecordingWriter | None = None
        self.recorder: Recorder | None = None
        self._cleanups: list[Callable[[], None]] = []
        self._closed = False
        self._loop: VirtualTimeLoop | None = None
        self._previous_source: TimeSource | None = None
        try:
            if not isinstance(time, Virtual | RealTime):
                raise TypeError(f"time= takes Virtual() or RealTime(scale), got {time!r}")
            self.time = time
            realtime = time.clock(hal)
            self.realtime_clock: RealTimeClock | None = realtime
            if record_to is not None:
                # A path, or a writer of the caller's (e.g. a RotatingRecordingWriter)
                # that the session then owns and finishes.
                self.writer = (
                    record_to
                    if isinstance(record_to, RecordingWriter)
                    else RecordingWriter(record_to)
                )
                # Before the first message, so a cut-off file still says its world.
                self.writer.add_metadata(WORLD_METADATA, world_metadata(hal))
                self.recorder = Recorder(self.writer)
            first = [self.recorder] if self.recorder is not None else []
            self.system = System([*first, *actors], clock=realtime, restart=restart)
            if self.recorder is not None:
                # A full disk stops the run cleanly (every on_stop runs); the owner of
                # the session raises the writer's DiskFullError once it is closed.
                self.recorder.on_disk_full = lambda _exc: self.system.stop()
            attach_rosout(self.system)
        except BaseException:
            try:
                if self.writer is not None:
                    self.writer.finish()
            finally:
                hal.close()
            raise

    @property
    def clock(self) -> Clock:
        """Sim time of this session (in virtual time: once the loop runs)."""
        return self.system.clock

    @property
    def closed(self) -> bool:
        return self._closed

    def add_cleanup(self, cleanup: Callable[[], None]) -> None:
        """Call ``cleanup()`` at teardown, after the recording is finished and before the
        world closes (last added, first called): e.g. closing a viewer window."""
        self._cleanups.append(cleanup)

    # -- running ------------------------------------------------------------------------

    @contextlib.asynccontextmanager
    async def running(self, *, close: bool = True) -> AsyncIterator[System]:
        """The system running for the body of the ``async with``. On exit the actors
        stop (robot actors first, the recorder last) and, with ``close``, the session
        is torn down (:meth:`close`)."""
        try:
            self._take_time()
            pacer = self._start_pacer()
            try:
                async with self.system:
                    yield self.system
            finally:
                if pacer is not None:
                    pacer.cancel()
                    await asyncio.wait((pacer,))
        finally:
            if close:
                self.close()

    async def run(self, *, close: bool = True) -> None:
        """Run until every actor's ``run`` returned or the system is stopped
        (``session.system.stop()``) or an actor crashed; then as :meth:`running`."""
        async with self.running(close=close) as system:
            await system.wait_finished()

    def _take_time(self) -> None:
        if self.realtime_clock is not None:
            return
        loop = asyncio.get_running_loop()
        if not isinstance(loop, VirtualTimeLoop):
            raise RuntimeError(
                "a stack in virtual time needs a running VirtualTimeLoop (a test marked "
                "@pytest.mark.sim, or asyncio.Runner(loop_factory=virtual_loop_factory())); "
                "for real-time mode on this loop, ask for it (time=RealTime(scale))"
            )
        if loop.source is not self.hal:
            self._loop, self._previous_source = loop, loop.source
            loop.attach_source(self.hal)

    def _start_pacer(self) -> asyncio.Task[None] | None:
        clock = self.realtime_clock
        if clock is None or clock.max_batch_ticks is None:
            return None
        return asyncio.get_running_loop().create_task(clock.pace(), name="otonav-pacer")

    # -- teardown -----------------------------------------------------------------------

    def drain(self) -> None:
        """Write everything the recorder's funnel still holds (no-op without one)."""
        if self.recorder is not None and self.recorder.wired:
            self.recorder.drain()

    def close(self, *, epilogue: Callable[[RecordingWriter], None] | None = None) -> None:
        """Steps 3-6 of the module docstring: final drain, ``epilogue(writer)`` (only
        when recording), writer finished, cleanups, world closed, time source restored.
        Call it once the system has exited. Idempotent; every step runs even if an
        earlier one raised."""
        if self._closed:
            return
        self._closed = True
        try:
            try:
                if self.writer is not None:
                    try:
                        self.drain()
                        if epilogue is not None:
                            epilogue(self.writer)
                    finally:
                        self.writer.finish()
            finally:
                try:
                    self._run_cleanups()
                finally:
                    self.hal.close()
        finally:
            self._give_time_back()

    def _run_cleanups(self) -> None:
        failure: BaseException | None = None
        while self._cleanups:
            try:
                self._cleanups.pop()()
            except BaseException as exc:  # the others and the world still close
                failure = failure or exc
        if failure is not None:
            raise failure

    def _give_time_back(self) -> None:
        loop, previous = self._loop, self._previous_source
        self._loop = self._previous_source = None
        if (
            loop is not None
            and previous is not None
            and not loop.is_closed()
            and (loop.source is self.hal or getattr(loop.source, "failed", None) is self.hal)
        ):
            loop.attach_source(previous)
