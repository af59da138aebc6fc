"""One writer per output: an exclusive lock on an ``--out`` directory or file.

Two runs into one ``--out`` used to both exit 0 and both name ``out/recording.mcap``,
which then held only the second run's data (issue 27). Every surface that writes
artifacts (``run``, ``sweep``, ``replay --out``, the service's per-run directories, via
:func:`~otonav.scenario.run_scenario`) holds this lock while it writes; a second writer is
refused at once with :class:`OutputBusyError` (the CLI: one line, exit 2) before it
touches a file.

How: ``flock(LOCK_EX | LOCK_NB)`` on the directory itself (Linux and macOS lock a
directory's descriptor like a file's), so nothing is left behind, and the kernel drops
the lock when the holder dies, even by SIGKILL: a stale lock cannot exist. A file output
(``replay --out FILE``) locks the file, created empty if it did not exist (and removed
again if it is still empty when the lock is released). Without ``fcntl`` (Windows) no
lock is taken.

The lock is re-entrant within a thread (the CLI holds it around a run that takes it
again) and exclusive between threads (two service runs into one directory) and
processes.
"""

from __future__ import annotations

import contextlib
import os
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from otonav.errors import UsageError

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows: no lock
    fcntl = None  # type: ignore[assignment]


class OutputBusyError(UsageError):
    """Another run is writing to the same output: one line naming it and the way out."""


@dataclass(slots=True)
class _Held:
    fd: int
    thread: int
    depth: int


_held: dict[str, _Held] = {}
_guard = threading.Lock()


def _holder_pid(fd: int) -> int | None:
    """The pid holding a flock on ``fd``'s inode, from /proc/locks (Linux; None elsewhere)."""
    st = os.fstat(fd)
    dev = f"{os.major(st.st_dev):02x}:{os.minor(st.st_dev):02x}:{st.st_ino}"
    with contextlib.suppress(OSError):
        for line in Path("/proc/locks").read_text().splitlines():
            fields = line.split()
            if len(fields) >= 6 and fields[1] == "FLOCK" and fields[5] == dev:
                with contextlib.suppress(ValueError):
                    return int(fields[4])
    return None


def _busy(path: Path, what: str, pid: int | None) -> OutputBusyError:
    who = f"another otonav process (pid {pid})" if pid else "another otonav run"
    return OutputBusyError(
        f"{what} {path}: {who} is writing there; wait for it to finish or choose another {what}"
    )


class OutputPathError(UsageError):
    """An output path that names the wrong kind of thing (a file for a directory, or
    the other way round): one line saying which and what the option expects."""


def _check_kind(path: Path, what: str, is_file: bool) -> None:
    if is_file and path.is_dir():
        raise OutputPathError(
            f"{what} {path}: is a directory; {what} names the MCAP file to write "
            f"(e.g. {path / 'replayed.mcap'})"
        )
    blocking = next((p for p in (path, *path.parents) if p.exists() and not p.is_dir()), None)
    if blocking is not None and (blocking != path or not is_file):
        where = "is" if blocking == path else f"is inside {blocking}, which is"
        expects = "the MCAP file to write" if is_file else "the directory the run writes into"
        raise OutputPathError(
            f"{what} {path}: {where} a file, not a directory; {what} names {expects} "
            "(remove that file or choose another path)"
        )


@contextlib.contextmanager
def lock_output(path: Path, *, what: str = "--out", is_file: bool = False) -> Iterator[Path]:
    """Hold the exclusive lock on the output ``path`` (a directory, created if missing;
    with ``is_file``, a file) for the ``with`` block. Raises :class:`OutputBusyError`
    when another thread or process holds it; ``what`` names the option in the message."""
    created = False
    _check_kind(path, what, is_file)
    if is_file:
        path.parent.mkdir(parents=True, exist_ok=True)
        created = not path.exists()
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    else:
        path.mkdir(parents=True, exist_ok=True)
        fd = os.open(path, os.O_RDONLY)
    key = str(path.resolve())
    me = threading.get_ident()
    with _guard:
        held = _held.get(key)
        if held is not None:
            os.close(fd)
            if held.thread != me:
                raise _busy(path, what, os.getpid())
            held.depth += 1
            fd = -1
        else:
            if fcntl is not None:
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                except BlockingIOError:
                    pid = _holder_pid(fd)
                    os.close(fd)
                    raise _busy(path, what, pid) from None
            _held[key] = held = _Held(fd, me, 1)
    try:
        yield path
    finally:
        with _guard:
            held.depth -= 1
            if held.depth == 0:
                del _held[key]
                if created and _still_empty(path, held.fd):
                    with contextlib.suppress(OSError):
                        path.unlink()
                os.close(held.fd)  # releases the flock


def _still_empty(path: Path, fd: int) -> bool:
    """``path`` is still the empty file the lock created (not a file renamed over it)."""
    try:
        here = os.stat(path)
    except OSError:
        return False
    held = os.fstat(fd)
    return held.st_size == 0 and (here.st_dev, here.st_ino) == (held.st_dev, held.st_ino)
