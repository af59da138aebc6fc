"""Runs in the calling process, one after another: no start-up cost, no isolation (a
crash takes the caller down; a hang is caught only by the loop's own wall ceiling).
For debugging, tests and tiny sweeps."""

from __future__ import annotations

import shutil
import tempfile
import threading
from collections.abc import Sequence
from pathlib import Path

from otonav.sweep._plan import RunTask
from otonav.sweep._worker import execute
from otonav.sweep.backends import Emit


class InlineBackend:
    name = "inline"

    def run(self, tasks: Sequence[RunTask], emit: Emit, stop: threading.Event) -> None:
        scratch = Path(tempfile.mkdtemp(prefix="otonav-sweep-"))
        try:
            for task in tasks:
                if stop.is_set():
                    return
                emit(task, execute(task, scratch))
        finally:
            shutil.rmtree(scratch, ignore_errors=True)
