"""Where runs execute: in this process (``inline``), on a pool of warm local worker
processes (``process``, the default), or on a Ray cluster (``ray``). Each takes the
tasks, calls ``emit(task, outcome)`` in the caller's thread as each run finishes, and
returns when all are done or ``stop`` is set."""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from typing import Protocol

from otonav.sweep._plan import RunTask
from otonav.sweep._worker import RunOutcome

Emit = Callable[[RunTask, RunOutcome], None]


class Backend(Protocol):
    """Where a sweep's runs execute: a process pool, Ray, or one process."""

    name: str

    def run(self, tasks: Sequence[RunTask], emit: Emit, stop: threading.Event) -> None: ...


def error_outcome(task: RunTask, reason: str, wall_time_s: float, worker: str) -> RunOutcome:
    """A run the worker never answered for (it died or hung)."""
    return RunOutcome(
        run_id=task.run_id,
        status="error",
        reason=reason,
        figures={},
        recording_sha256=None,
        wall_time_s=wall_time_s,
        worker=worker,
    )


def hang_deadline(task: RunTask) -> float:
    """Wall seconds after which a run's worker is killed: the run's own ceiling (the
    loop enforces it between steps) plus a margin for a hang the loop cannot see."""
    return task.wall_ceiling_s + max(1.0, 0.1 * task.wall_ceiling_s)


__all__ = ("Backend", "Emit", "error_outcome", "hang_deadline")
