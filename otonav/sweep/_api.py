"""The Python API for services and notebooks.

:func:`sweep_results` iterates the records of a sweep as runs finish. The sweep itself
runs in a thread of its own (driving worker processes or Ray), never on the caller's
event loop, which keeps serving. Leaving the iteration early (``break``, an exception,
cancelling the task that iterates) stops the sweep: no new run starts, runs in flight
are dropped (their workers killed), and every record already yielded is on disk, so
``resume=True`` finishes the sweep later. :func:`run_sweep` is the blocking form.
"""

from __future__ import annotations

import asyncio
import threading
from collections.abc import AsyncIterator, Sequence
from pathlib import Path
from typing import Any

from otonav.sweep import _runner as runner
from otonav.sweep._plan import RunTask
from otonav.sweep._report import summarize, write_report
from otonav.sweep._spec import SweepSpec

_DONE = object()
BACKEND = "process"
"""Where the runs go unless told (``otonav sweep --backend`` says it again)."""
_NAME: str = SweepSpec.model_fields["name"].default


async def sweep_results(
    tasks: Sequence[RunTask],
    *,
    out: Path,
    backend: str = BACKEND,
    workers: int | None = None,
    ray_address: str | None = None,
    resume: bool = False,
    retry_errors: bool = False,
    report: bool = True,
    name: str = _NAME,
) -> AsyncIterator[dict[str, Any]]:
    """Yield one record (the line written to ``results.jsonl``) per run as it finishes.
    With ``report``, a sweep that ran to its end also writes ``summary.json`` and
    ``report.md``. Errors in the sweep's arguments (a used ``out``, an unknown backend)
    raise :class:`~otonav.stack._files.ConfigFileError` before anything runs."""
    loop = asyncio.get_running_loop()
    prepared = await asyncio.to_thread(
        runner.prepare,
        out,
        tasks,
        resume=resume,
        retry_errors=retry_errors,
        meta={"name": name, "api": True},
    )
    engine = runner.make_backend(backend, workers=workers, ray_address=ray_address)
    queue: asyncio.Queue[Any] = asyncio.Queue()
    stop = threading.Event()
    finished = loop.create_future()

    def deliver(item: Any) -> None:
        loop.call_soon_threadsafe(queue.put_nowait, item)

    def drive() -> None:
        outcome: Any = _DONE
        try:
            runner.execute(prepared, engine, stop=stop, on_record=deliver)
        except BaseException as exc:  # handed to the caller, raised there
            outcome = exc
        deliver(outcome)
        loop.call_soon_threadsafe(_settle, finished)

    thread = threading.Thread(target=drive, name=f"otonav-sweep:{name}", daemon=True)
    thread.start()
    completed = False
    try:
        while True:
            item = await queue.get()
            if item is _DONE:
                completed = not stop.is_set()
                break
            if isinstance(item, BaseException):
                raise item
            yield item
    finally:
        stop.set()
        if not finished.done():
            await asyncio.shield(finished)  # the workers are down when we return
    if completed and report:
        records = runner.all_records(prepared)
        summary = summarize(records, planned=len(prepared.tasks), name=name)
        await asyncio.to_thread(write_report, out, summary, records)


def _settle(future: asyncio.Future[None]) -> None:
    if not future.done():
        future.set_result(None)


def run_sweep(
    tasks: Sequence[RunTask],
    *,
    out: Path,
    backend: str = BACKEND,
    workers: int | None = None,
    ray_address: str | None = None,
    resume: bool = False,
    report: bool = True,
    name: str = _NAME,
) -> dict[str, Any]:
    """Run the sweep to its end in this thread; return its summary (see
    :func:`~otonav.sweep._report.summarize`)."""
    prepared = runner.prepare(out, tasks, resume=resume, meta={"name": name, "api": True})
    runner.execute(prepared, runner.make_backend(backend, workers=workers, ray_address=ray_address))
    records = runner.all_records(prepared)
    summary = summarize(records, planned=len(prepared.tasks), name=name)
    if report:
        write_report(out, summary, records)
    return summary
