"""Ray's processes die with the sweep that started them (issue 27).

A local Ray cluster started on demand (``ray.init``) is a tree of processes under the
driver. When the driver is SIGKILLed, Ray's own fate-sharing stops the raylet and the
workers within seconds, but its two agents (``ray::DashboardAgent`` and
``ray::RuntimeEnvAgent``, ~170 MB together) were measured alive 60-120 s later: they
see the raylet die, then wait on a GCS that is gone. Ray's pipe-based agent health check
(``RAY_enable_pipe_based_agent_to_parent_health_check=1``) did not change that (measured:
still alive 40 s later).

:func:`start_reaper` starts this module as a small watcher process before the cluster
starts. It notes the driver's descendants that are Ray's (their command line names Ray;
pid and start time, from ``/proc``) every
:data:`SCAN_S` for the first :data:`SETTLE_S` (the cluster starting: ~5 ms a look),
then every :data:`SCAN_SLOW_S`, and blocks on a pipe from the driver in between; end of file (the
driver exited, however: SIGKILL included) makes it kill every process it noted that is
still the same process (same start time: a reused pid is left alone), then exit.
Processes that set their title (``setproctitle``) overwrite their environment block,
so a mark in the environment would not find the agents; the tree does.

``python -m otonav.sweep.backends._reaper`` is the watcher's own entry point (Linux).
"""

from __future__ import annotations

import os
import select
import signal
import sys
import time

__all__ = ["SCAN_S", "SCAN_SLOW_S", "SETTLE_S", "descendants", "start_reaper"]

SCAN_S = 0.25
"""s between two looks at the driver's process tree while the cluster starts."""
SETTLE_S = 15.0
"""s after which the tree is looked at every :data:`SCAN_SLOW_S` only."""
SCAN_SLOW_S = 2.0

_WATCHER: list[int] = []
"""The watcher's pid and our end of its pipe, kept open for the life of this process
(the kernel closes it when the process exits, however it exits)."""


def start_reaper() -> int:
    """Start the watcher of this process's descendants; it lives until this process
    exits, then kills what is left of them. One per process: a second call returns
    the first watcher's pid."""
    if _WATCHER:
        return _WATCHER[0]
    read_end, write_end = os.pipe()  # both close-on-exec: no other child inherits ours
    devnull = os.devnull
    try:
        pid = os.posix_spawn(
            sys.executable,
            [sys.executable, "-m", "otonav.sweep.backends._reaper"],
            os.environ,
            file_actions=[
                (os.POSIX_SPAWN_DUP2, read_end, 0),
                (os.POSIX_SPAWN_OPEN, 1, devnull, os.O_WRONLY, 0),
                (os.POSIX_SPAWN_OPEN, 2, devnull, os.O_WRONLY, 0),
            ],
            setsid=True,  # a Ctrl-C to the sweep's terminal does not reach it
        )
    finally:
        os.close(read_end)
    _WATCHER.extend((pid, write_end))
    return pid


def _stat(pid: int) -> tuple[int, int] | None:
    """(parent pid, start time in clock ticks) of ``pid``; None if it is gone."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            data = f.read()
    except OSError:
        return None
    # The name (field 2) is in parentheses and may hold spaces: split after it.
    fields = data[data.rindex(b")") + 2 :].split()
    return int(fields[1]), int(fields[19])


def descendants(root: int) -> dict[int, int]:
    """pid -> start time of every process below ``root`` (Linux ``/proc``)."""
    parent: dict[int, int] = {}
    start: dict[int, int] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            stat = _stat(int(entry))
            if stat is not None:
                parent[int(entry)], start[int(entry)] = stat
    children: dict[int, list[int]] = {}
    for pid, ppid in parent.items():
        children.setdefault(ppid, []).append(pid)
    found: dict[int, int] = {}
    todo = list(children.get(root, ()))
    while todo:
        pid = todo.pop()
        found[pid] = start[pid]
        todo.extend(children.get(pid, ()))
    return found


def _is_ray(pid: int) -> bool:
    """``pid`` is one of Ray's processes (``ray::NAME``, raylet, gcs_server, Ray's Python
    services): its command line names Ray. Anything else the driver started is not ours
    to kill."""
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            cmdline = f.read()
    except OSError:
        return False
    return b"ray" in cmdline


def _watch(driver: int) -> dict[int, int]:
    """Note the driver's descendants that are Ray's until its pipe closes; return them."""
    seen: dict[int, int] = {}
    me = os.getpid()
    start = time.monotonic()
    while True:
        wait = SCAN_S if time.monotonic() - start < SETTLE_S else SCAN_SLOW_S
        readable, _, _ = select.select([sys.stdin.buffer], [], [], wait)
        if readable and not os.read(sys.stdin.buffer.fileno(), 4096):
            return seen  # end of file: the driver exited
        seen.update(
            (pid, started)
            for pid, started in descendants(driver).items()
            if pid not in seen and pid != me and _is_ray(pid)
        )


def _reap(seen: dict[int, int]) -> None:
    deadline = time.monotonic() + 10.0
    while seen and time.monotonic() < deadline:
        for pid, started in list(seen.items()):
            stat = _stat(pid)
            if stat is None or stat[1] != started:
                del seen[pid]  # gone (or the pid is another process's now)
                continue
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                del seen[pid]
        time.sleep(0.02)  # a killed process is a zombie until reaped: look again


def main() -> int:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _reap(_watch(os.getppid()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
