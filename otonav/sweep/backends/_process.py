"""A pool of warm local worker processes, supervised run by run.

Each worker is ``python -m otonav.sweep.backends._process FD``: an interpreter that
imports otonav once, says it is ready, then runs one task at a time from its socket (no
interpreter start per run: the ~1 s of imports is paid once per worker). Tasks and
outcomes travel as pickles over a ``multiprocessing.connection.Connection`` on a
socketpair. The parent waits on every worker's connection at once
(``multiprocessing.connection.wait``), so it sees at the same moment a result, a worker
that died (its connection reaches EOF: the run becomes an ``error`` and a fresh worker
takes its place) and a run past its wall ceiling (the worker is killed, same). One task
in flight per worker keeps a death from costing more than the run it was doing.

Not ``multiprocessing.Process``: its spawn start method re-imports the caller's
``__main__`` in every worker (a notebook or a script without a main guard would run
again), and fork would copy a parent that may hold threads. Not
``concurrent.futures.ProcessPoolExecutor``: one dead worker breaks the whole executor
(``BrokenProcessPool``), and it cannot kill one hung task.

Workers ignore SIGINT (a Ctrl-C on the terminal reaches the whole process group: the
parent decides what stops) and exit by themselves when the parent goes away (EOF).
"""

from __future__ import annotations

import asyncio
import contextlib
import multiprocessing.connection
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from multiprocessing.connection import Connection
from pathlib import Path

from otonav.sweep._plan import RunTask
from otonav.sweep._worker import RunOutcome
from otonav.sweep.backends import Emit, error_outcome, hang_deadline

_READY = "ready"
#: Longest the parent blocks before looking at ``stop`` again (s, wall).
_POLL_S = 0.2
_PACKAGE_ROOT = str(Path(__file__).resolve().parents[3])


def _worker_main(fd: int, scratch: Path) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    from otonav.sweep._worker import WarmWorker  # the imports a worker pays once

    worker = WarmWorker(scratch)
    conn = Connection(fd)
    conn.send(_READY)
    while True:
        try:
            task = conn.recv()
        except (EOFError, OSError):  # the parent is gone
            return
        if task is None:
            return
        try:
            outcome = worker.run(task)
        except (KeyboardInterrupt, asyncio.CancelledError):  # SIGTERM to the process group:
            return  # the run was cancelled (recording finished); the parent decides the rest
        conn.send(outcome)


@dataclass
class _Worker:
    proc: subprocess.Popen[bytes]
    conn: Connection
    scratch: Path
    ready: bool = False
    task: RunTask | None = None
    started: float = 0.0

    @property
    def name(self) -> str:
        return f"{socket.gethostname()}:{self.proc.pid}"


def _exit_description(code: int | None) -> str:
    if code is not None and code < 0:
        try:
            return f"killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exited with code {code}"


class ProcessBackend:
    name = "process"

    def __init__(self, workers: int | None = None) -> None:
        self.workers = workers or len(os.sched_getaffinity(0))
        self._root = Path(tempfile.gettempdir())
        self._spawned = 0

    def _spawn(self) -> _Worker:
        self._spawned += 1
        scratch = self._root / f"w{self._spawned}"
        scratch.mkdir()
        ours, theirs = socket.socketpair()
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (_PACKAGE_ROOT, env.get("PYTHONPATH")) if p)
        proc = subprocess.Popen(
            [sys.executable, "-m", __name__, str(theirs.fileno()), str(scratch)],
            pass_fds=(theirs.fileno(),),
            stdin=subprocess.DEVNULL,
            env=env,
        )
        theirs.close()
        return _Worker(proc, Connection(ours.detach()), scratch)

    def run(self, tasks: Sequence[RunTask], emit: Emit, stop: threading.Event) -> None:
        queue = deque(tasks)
        self._root = Path(tempfile.mkdtemp(prefix="otonav-sweep-"))
        pool = [self._spawn() for _ in range(min(self.workers, len(queue)))]
        try:
            while not stop.is_set():
                for w in pool:
                    if w.ready and w.task is None and queue:
                        w.task, w.started = queue.popleft(), time.perf_counter()
                        w.conn.send(w.task)
                if not queue and all(w.task is None for w in pool):
                    return
                self._wait(pool, emit, stop)
        finally:
            self._shutdown(pool)

    def _wait(self, pool: list[_Worker], emit: Emit, stop: threading.Event) -> None:
        now = time.perf_counter()
        timeout = _POLL_S
        for w in pool:
            if w.task is not None:
                timeout = min(timeout, max(0.0, w.started + hang_deadline(w.task) - now))
        ready = multiprocessing.connection.wait([w.conn for w in pool], timeout)
        for i, w in enumerate(pool):
            dead = False
            if w.conn in ready:
                try:
                    message = w.conn.recv()
                except (EOFError, OSError):
                    dead = True
                else:
                    if message == _READY:
                        w.ready = True
                    elif w.task is not None:
                        task, w.task = w.task, None
                        emit(task, message)
            if dead:
                code = w.proc.wait()
                if stop.is_set():  # a stop's signal may reach the workers too: their runs
                    w.task = None  # are unfinished, not errors, and nothing replaces them
                    continue
                if not w.ready:
                    raise RuntimeError(
                        f"a sweep worker failed to start ({_exit_description(code)}); "
                        "run `python -c 'import otonav.sweep._worker'` to see why"
                    )
                if w.task is not None:
                    reason = f"worker died ({_exit_description(code)}) during this run"
                    emit(w.task, self._lost(w, reason))
                pool[i] = self._replace(w)
            elif w.task is not None and time.perf_counter() - w.started > hang_deadline(w.task):
                w.proc.kill()
                w.proc.wait()
                reason = (
                    f"hung: no result after {hang_deadline(w.task):g} s of wall time "
                    f"(wall_ceiling_s {w.task.wall_ceiling_s:g}); worker killed"
                )
                emit(w.task, self._lost(w, reason))
                pool[i] = self._replace(w)

    @staticmethod
    def _lost(w: _Worker, reason: str) -> RunOutcome:
        assert w.task is not None
        return error_outcome(w.task, reason, time.perf_counter() - w.started, w.name)

    def _replace(self, dead: _Worker) -> _Worker:
        dead.conn.close()
        shutil.rmtree(dead.scratch, ignore_errors=True)
        return self._spawn()

    def _shutdown(self, pool: list[_Worker]) -> None:
        for w in pool:
            if w.task is None and w.proc.poll() is None:
                with contextlib.suppress(OSError):
                    w.conn.send(None)
            else:  # interrupted mid-run: that run is simply not finished
                w.proc.kill()
        for w in pool:
            try:
                w.proc.wait(timeout=5.0)
            except subprocess.TimeoutExpired:
                w.proc.kill()
                w.proc.wait()
            w.conn.close()
        shutil.rmtree(self._root, ignore_errors=True)


if __name__ == "__main__":
    _worker_main(int(sys.argv[1]), Path(sys.argv[2]))
