"""A SIGKILLed Ray sweep leaves no Ray process behind (issue 27 item 9).

A real ``otonav sweep --backend ray`` process is killed with SIGKILL once its first run
has finished; every process below it (Ray's GCS, raylet, agents and workers, ~170 MB
for the two agents alone, which outlived the driver by 60-120 s) must be gone. The
test waits on a pidfd per process (woken by its exit, no polling); its 30 s bound only
catches a hang."""

from __future__ import annotations

import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from otonav.sweep._results import read_results

pytestmark = pytest.mark.sil


def _tree(root: int) -> dict[int, tuple[int, str]]:
    """pid -> (start time, name) of every process below ``root``, from /proc."""
    info: dict[int, tuple[int, int, str]] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            data = Path(f"/proc/{entry}/stat").read_bytes()
            name = Path(f"/proc/{entry}/cmdline").read_bytes().replace(b"\0", b" ").decode()
        except OSError:
            continue
        fields = data[data.rindex(b")") + 2 :].split()
        info[int(entry)] = (int(fields[1]), int(fields[19]), name.strip())
    found: dict[int, tuple[int, str]] = {}
    todo = [root]
    while todo:
        parent = todo.pop()
        for pid, (ppid, started, name) in info.items():
            if ppid == parent and pid not in found:
                found[pid] = (started, name)
                todo.append(pid)
    return found


def _alive(pid: int, started: int) -> bool:
    try:
        data = Path(f"/proc/{pid}/stat").read_bytes()
    except OSError:
        return False
    fields = data[data.rindex(b")") + 2 :].split()
    return int(fields[19]) == started and fields[0] != b"Z"


def _wait_gone(tree: dict[int, tuple[int, str]], timeout: float) -> dict[int, tuple[int, str]]:
    """Wait until every process of ``tree`` has exited, or ``timeout`` s (a hang guard);
    return those still alive. A pidfd is readable once its process has exited."""
    fds: dict[int, int] = {}
    poller = select.poll()
    try:
        for pid, (started, _name) in tree.items():
            try:
                fd = os.pidfd_open(pid)
            except ProcessLookupError:
                continue
            if not _alive(pid, started):  # gone, or the pid reused, before the open
                os.close(fd)
                continue
            fds[fd] = pid
            poller.register(fd, select.POLLIN)
        deadline = time.monotonic() + timeout
        while fds and (remaining := deadline - time.monotonic()) > 0:
            for fd, _event in poller.poll(remaining * 1000):
                poller.unregister(fd)
                os.close(fd)
                del fds[fd]
    finally:
        for fd in fds:
            os.close(fd)
    return {pid: tree[pid] for pid in fds.values() if _alive(pid, tree[pid][0])}


def test_ray_processes_die_with_a_sigkilled_sweep(tmp_path: Path) -> None:
    (tmp_path / "worlds").mkdir()
    (tmp_path / "worlds" / "short.yaml").write_text(
        "name: short\nscene: empty\ngoal: {x: 1.0, y: 0.3}\nsim_budget: 4.0\n"
    )
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text("name: k\nscenarios: ['worlds/*.yaml']\nseeds: {start: 0, count: 40}\n")
    out = tmp_path / "out"
    env = {**os.environ, "HOME": str(tmp_path)}  # Ray leaves its files in a home of ours
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "otonav",
            "sweep",
            str(sweep),
            "--out",
            str(out),
            "--backend",
            "ray",
            "--workers",
            "2",
        ],
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        text=True,
        env=env,
    )
    tree: dict[int, tuple[int, str]] = {}
    try:
        assert proc.stderr is not None
        for line in proc.stderr:  # one line per finished run (not a terminal)
            if line.startswith("sweep: ["):
                break
        else:
            pytest.fail(f"the sweep ended before its first run: exit {proc.wait()}")
        tree = _tree(proc.pid)
        names = " | ".join(name for _s, name in tree.values())
        assert "ray::DashboardAgent" in names, names  # the ones that used to outlive it
        assert "ray::SweepActor" in names, names
        proc.send_signal(signal.SIGKILL)
        assert proc.wait(timeout=30) == -signal.SIGKILL
        left = _wait_gone(tree, timeout=30.0)  # a hang guard, not the figure under test
        assert not left, f"still alive after the sweep was SIGKILLed: {left}"
        assert len(read_results(out / "results.jsonl")) >= 1
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        if proc.stderr is not None:
            proc.stderr.close()
        for pid, (started, _name) in tree.items():  # never leave them to the next test
            if _alive(pid, started):
                os.kill(pid, signal.SIGKILL)
