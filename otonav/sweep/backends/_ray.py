"""Runs on a Ray cluster: a local one started on demand (``ray.init(num_cpus=N)``), or
an existing one (``address``, e.g. ``ray://head:10001`` or ``auto``).

One Ray actor per worker slot keeps otonav imported (warm, like the process pool's
workers) and runs one task at a time; the driver keeps one task in flight per actor and
waits on all of them (``ray.wait``), so a dead actor (``RayActorError``) or a run past
its wall ceiling (the actor is killed) costs only that run, recorded as an ``error``,
and a fresh actor takes the slot. Outcomes come back through Ray's object store, kept
artifacts included as bytes, and the driver writes them into ``--out``: remote workers
need no shared filesystem (docs/adr/0018-sweep-backends-and-artifacts.md). Every node
needs otonav installed (the same version) in the Python that runs Ray.

A cluster started on demand keeps Ray's token authentication on but leaves nothing in
the user's home: unless the caller set ``RAY_AUTH_MODE``, ``RAY_AUTH_TOKEN`` or
``RAY_AUTH_TOKEN_PATH``, it gets a random token in the environment (``RAY_AUTH_TOKEN``,
inherited by the cluster's processes) instead of Ray writing ``~/.ray/auth_token``
(docs/adr/0029-sweep-memory-and-ray-state.md).

On Linux such a cluster dies with the process that started it, even by SIGKILL: a small
watcher process kills what is left of it (:mod:`otonav.sweep.backends._reaper`).
"""

from __future__ import annotations

import logging
import os
import secrets
import shutil
import sys
import tempfile
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from otonav.sweep._plan import RunTask
from otonav.sweep._worker import RunOutcome
from otonav.sweep.backends import Emit, error_outcome, hang_deadline

_POLL_S = 0.2
_AUTH_VARS = ("RAY_AUTH_MODE", "RAY_AUTH_TOKEN", "RAY_AUTH_TOKEN_PATH")


def init_local(num_cpus: int, **kwargs: Any) -> None:
    """Start a local Ray cluster of ``num_cpus`` CPUs for this process, with token
    authentication and no file in the user's home (see the module's docstring)."""
    import ray

    if not any(os.environ.get(name) for name in _AUTH_VARS):
        # With the mode unset, ray.init turns token authentication on (in this process
        # too: setting the mode here would come after `import ray` read its config) and
        # finds this token instead of writing one. Process-wide on purpose: the
        # cluster's processes inherit it, and Ray's token loader caches what it read.
        os.environ["RAY_AUTH_TOKEN"] = secrets.token_hex(32)
    if sys.platform == "linux":
        from otonav.sweep.backends._reaper import start_reaper

        start_reaper()  # the cluster dies with this process, SIGKILL included
    options: dict[str, Any] = {
        "include_dashboard": False,
        "logging_level": logging.WARNING,
        "log_to_driver": False,
    }
    ray.init(num_cpus=num_cpus, **{**options, **kwargs})


class SweepActor:
    """A warm worker on a Ray node: otonav imported once, a private scratch dir."""

    def __init__(self) -> None:
        from otonav.sweep import _worker as worker

        self._scratch = Path(tempfile.mkdtemp(prefix="otonav-sweep-ray-"))
        self._worker = worker.WarmWorker(self._scratch)
        self._name = worker.worker_name()

    def ready(self) -> str:
        return self._name

    def run(self, task: RunTask) -> RunOutcome:
        return self._worker.run(task)

    def close(self) -> None:
        shutil.rmtree(self._scratch, ignore_errors=True)


@dataclass
class _Slot:
    actor: Any
    ready_ref: Any | None
    task: RunTask | None = None
    ref: Any | None = None
    started: float = 0.0
    name: str = "ray-actor"


class RayBackend:
    name = "ray"

    def __init__(self, workers: int | None = None, *, address: str | None = None) -> None:
        try:
            import ray  # noqa: F401
        except ImportError:
            from otonav.stack._files import ConfigFileError

            raise ConfigFileError(
                "--backend ray: Ray is not installed; pip install 'otonav[ray]'"
            ) from None
        self.workers = workers
        self.address = address

    def run(self, tasks: Sequence[RunTask], emit: Emit, stop: threading.Event) -> None:
        import ray

        started_here = False
        if not ray.is_initialized():
            if self.address:
                ray.init(address=self.address, logging_level=logging.WARNING)
            else:
                init_local(self.workers or len(os.sched_getaffinity(0)))
                started_here = True
        remote = ray.remote(num_cpus=1, max_restarts=0)(SweepActor)
        cpus = int(ray.cluster_resources().get("CPU", 1))  # type: ignore[no-untyped-call]
        count = min(self.workers or cpus, len(tasks))
        slots = [self._slot(remote) for _ in range(count)]
        queue = list(reversed(tasks))
        try:
            while not stop.is_set():
                for s in slots:
                    if s.ready_ref is None and s.task is None and queue:
                        s.task, s.started = queue.pop(), time.perf_counter()
                        s.ref = s.actor.run.remote(s.task)
                if not queue and all(s.task is None for s in slots):
                    return
                self._wait(ray, remote, slots, emit)
        finally:
            for s in slots:
                ray.kill(s.actor)
            if started_here:
                ray.shutdown()

    @staticmethod
    def _slot(remote: Any) -> _Slot:
        actor = remote.remote()
        return _Slot(actor, actor.ready.remote())

    def _wait(self, ray: Any, remote: Any, slots: list[_Slot], emit: Emit) -> None:
        now = time.perf_counter()
        timeout = _POLL_S
        for s in slots:
            if s.task is not None:
                timeout = min(timeout, max(0.0, s.started + hang_deadline(s.task) - now))
        refs = [r for s in slots for r in (s.ready_ref, s.ref) if r is not None]
        done, _ = ray.wait(refs, num_returns=len(refs), timeout=timeout)
        finished = set(done)
        for i, s in enumerate(slots):
            if s.ready_ref is not None and s.ready_ref in finished:
                try:
                    s.name = ray.get(s.ready_ref)
                except ray.exceptions.RayError as exc:
                    raise RuntimeError(f"a Ray sweep worker failed to start: {exc}") from None
                s.ready_ref = None
            if s.ref is not None and s.ref in finished:
                assert s.task is not None
                task, ref = s.task, s.ref
                s.task, s.ref = None, None
                try:
                    outcome = ray.get(ref)
                except ray.exceptions.RayActorError as exc:
                    reason = f"worker died during this run ({type(exc).__name__})"
                    emit(task, error_outcome(task, reason, time.perf_counter() - s.started, s.name))
                    slots[i] = self._slot(remote)
                    continue
                except ray.exceptions.RayError as exc:
                    reason = f"{type(exc).__name__}: {str(exc).splitlines()[0]}"
                    outcome = error_outcome(task, reason, time.perf_counter() - s.started, s.name)
                emit(task, outcome)
            elif s.task is not None and time.perf_counter() - s.started > hang_deadline(s.task):
                ray.kill(s.actor)
                reason = (
                    f"hung: no result after {hang_deadline(s.task):g} s of wall time "
                    f"(wall_ceiling_s {s.task.wall_ceiling_s:g}); worker killed"
                )
                elapsed = time.perf_counter() - s.started
                emit(s.task, error_outcome(s.task, reason, elapsed, s.name))
                slots[i] = self._slot(remote)
