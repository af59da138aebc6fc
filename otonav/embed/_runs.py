"""Fast simulations on request, off the host's loop: :func:`run_scenario_async`."""

from __future__ import annotations

import asyncio
import contextlib
import threading
import weakref
from collections.abc import Callable
from pathlib import Path

import anyio
import anyio.to_thread

from otonav.engine._live import _wait_done
from otonav.runtime import Actor
from otonav.scenario import ScenarioConfig, Verdict, run_scenario
from otonav.scenario._assembly import scenario_world
from otonav.scenario._run import SOURCE, WALL_CEILING
from otonav.stack import StackConfig

#: Simulations run at once through :func:`run_scenario_async` with the default limiter.
DEFAULT_MAX_RUNS = 2


_limiters: weakref.WeakKeyDictionary[asyncio.AbstractEventLoop, anyio.CapacityLimiter] = (
    weakref.WeakKeyDictionary()
)


def default_limiter() -> anyio.CapacityLimiter:
    """The running loop's shared limiter for :func:`run_scenario_async`
    (:data:`DEFAULT_MAX_RUNS` at once; set ``.total`` to change it)."""
    loop = asyncio.get_running_loop()
    limiter = _limiters.get(loop)
    if limiter is None:
        limiter = anyio.CapacityLimiter(DEFAULT_MAX_RUNS)
        _limiters[loop] = limiter
    return limiter


_OnStart = Callable[[asyncio.AbstractEventLoop, asyncio.Task[None]], None]


class _RunControl:
    """Cancels a run on its own loop, from the host's thread, whenever it is asked."""

    def __init__(self, on_start: _OnStart | None) -> None:
        self._lock = threading.Lock()
        self._user_on_start = on_start
        self._loop: asyncio.AbstractEventLoop | None = None
        self._task: asyncio.Task[None] | None = None
        self.cancel_requested = False

    def on_start(self, loop: asyncio.AbstractEventLoop, task: asyncio.Task[None]) -> None:
        with self._lock:
            self._loop, self._task = loop, task
            cancel = self.cancel_requested
        if self._user_on_start is not None:
            self._user_on_start(loop, task)
        if cancel:
            task.cancel()  # we are on the run's loop

    def cancel(self) -> None:
        with self._lock:
            self.cancel_requested = True
            loop, task = self._loop, self._task
        if loop is not None and task is not None:
            with contextlib.suppress(RuntimeError):  # the run's loop already closed
                loop.call_soon_threadsafe(task.cancel)


def check_run(
    scenario: ScenarioConfig, stack: StackConfig = StackConfig(), *, source: str = SOURCE
) -> None:
    """Raise what :func:`run_scenario_async` (and the CLI) would reject before running:
    an unknown or broken scene (:class:`~otonav.hal.mujoco.SceneError`), a goal outside
    the arena or on an obstacle (:class:`~otonav.stack._files.ConfigFileError`). Builds
    the world once (milliseconds): call it from a worker thread on a busy loop."""
    _scenario, _stack, hal = scenario_world(scenario, stack, source=source)
    hal.close()


async def run_scenario_async(
    scenario: ScenarioConfig = ScenarioConfig(),
    stack: StackConfig = StackConfig(),
    *,
    out_dir: Path | None,
    record: bool = True,
    plot: bool = True,
    wall_ceiling: float | None = WALL_CEILING,
    extra_actors: tuple[Actor, ...] = (),
    limiter: anyio.CapacityLimiter | None = None,
    on_start: _OnStart | None = None,
    source: str = SOURCE,
) -> Verdict:
    """:func:`~otonav.scenario.run_scenario` in a worker thread, on its own virtual-time
    loop, while the caller's loop keeps serving. Returns the same verdict (and
    byte-identical recording) as the CLI for the same scenario and config.

    ``limiter``: at most ``limiter.total`` runs at once (default: :func:`default_limiter`,
    2 per loop); a run waits for a slot before it starts. ``on_start(loop, task)`` is
    called in the worker thread as the run starts. ``source`` names the scenario in
    configuration errors (:class:`~otonav.stack._files.ConfigFileError`, raised before
    anything runs), as the CLI does.

    Cancelling the caller (``task.cancel()`` or an anyio cancel scope) cancels the
    simulation on its loop and waits for it to end, so its ``recording.mcap`` is
    finished and indexed when the cancellation reaches the caller. A run cancelled
    while still waiting for a slot never starts and leaves nothing.
    """
    control = _RunControl(on_start)

    def work() -> Verdict | None:
        try:
            return run_scenario(
                scenario,
                stack,
                out_dir=out_dir,
                record=record,
                plot=plot,
                wall_ceiling=wall_ceiling,
                extra_actors=extra_actors,
                on_start=control.on_start,
                source=source,
            )
        except asyncio.CancelledError:
            if control.cancel_requested:
                return None
            raise

    async with limiter if limiter is not None else default_limiter():
        # The thread runs in a task of its own that nothing cancels: the caller's
        # cancellation is turned into the simulation's, then waited out.
        worker = asyncio.get_running_loop().create_task(
            anyio.to_thread.run_sync(work), name=f"otonav-run:{scenario.name}"
        )
        try:
            verdict = await asyncio.shield(worker)
        except asyncio.CancelledError:
            if worker.cancelled():
                raise
            control.cancel()
            await _wait_done(worker)
            if not worker.cancelled():
                worker.exception()  # retrieved: a run cancelled late may have failed
            raise
    if verdict is None:  # pragma: no cover - only when cancelled, handled above
        raise asyncio.CancelledError
    return verdict
