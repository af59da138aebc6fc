"""The CLI's log lines: one line per warning or error on stderr, and a node's own lines
as ROS 2 prints them (``[WARN] [1.250] [wander]: scan is old``).

The runtime logs an actor's crash with its whole traceback (``otonav.runtime._system``);
the recording keeps that traceback on ``/rosout``. On a terminal Python's fallback
handler printed all of it (65 lines for one crash, issue 27): here a crash becomes its
first line and the exception it ended with, plus the frames of the user's own code when
the crash came from there (the runtime's and the libraries' frames left out; issue 39).
"""

from __future__ import annotations

import logging
import re
import sys
import sysconfig
from pathlib import Path

_MARK = "_otonav_cli_handler"
_NODES = "otonav.node"
"""``otonav.runtime._nodelog.LOGGER_NAME``, not imported: the runtime pulls in anyio, and
every command installs this handler (``otonav --help`` stays light)."""
_LEVELS = {10: "DEBUG", 20: "INFO", 30: "WARN", 40: "ERROR", 50: "FATAL"}
_FRAME = re.compile(r'^  File "(?P<file>[^"]+)", line \d+')
_NOT_USERS = tuple(
    str(Path(p).resolve())
    for p in (
        Path(__file__).parents[1],  # otonav itself
        sysconfig.get_paths()["stdlib"],
        sysconfig.get_paths()["purelib"],
        sysconfig.get_paths()["platlib"],
    )
)


def user_frames(traceback_text: str) -> list[str]:
    """The lines of ``traceback_text``'s frames that are in the user's code (not in
    otonav, the standard library or an installed package)."""
    kept: list[str] = []
    keep = False
    for line in traceback_text.splitlines():
        frame = _FRAME.match(line)
        if frame:
            keep = not str(Path(frame["file"]).resolve()).startswith(_NOT_USERS)
        elif not line.startswith("    "):
            keep = False
        if keep:
            kept.append(line)
    return kept


class OneLineFormatter(logging.Formatter):
    """``otonav: [0.500] nav crashed: RuntimeError: boom (traceback on /rosout)``."""

    def format(self, record: logging.LogRecord) -> str:
        node = getattr(record, "otonav_node", None)
        if node is not None:
            level = _LEVELS.get(record.levelno, record.levelname)
            now = getattr(record, "sim_time", 0.0)
            return f"[{level}] [{now:.3f}] [{node}]: {record.getMessage()}"
        lines = [line for line in record.getMessage().splitlines() if line.strip()]
        if not lines:
            return "otonav:"
        head = lines[0].removesuffix("Traceback (most recent call last):").rstrip()
        if len(lines) == 1:
            return f"otonav: {head}"
        ending = f"otonav: {head}: {lines[-1].strip()}"
        frames = user_frames(record.getMessage())
        if not frames:
            return f"{ending} (traceback on /rosout in the recording)"
        return "\n".join([ending, "Traceback (your code; the rest is on /rosout):", *frames])


class _StderrHandler(logging.StreamHandler):  # type: ignore[type-arg]
    """Writes to whatever ``sys.stderr`` is when a record comes, not the one it was
    installed with: a host (pytest's capture) that swaps and closes it later would get
    "--- Logging error ---" and a traceback instead of the line."""

    def __init__(self) -> None:
        super().__init__(sys.stderr)

    @property
    def stream(self) -> object:
        return sys.stderr

    @stream.setter
    def stream(self, _value: object) -> None:
        pass


def install(*, verbose: bool = False) -> None:
    """Route the ``otonav`` loggers' warnings and errors to stderr, one line each, and
    with ``verbose`` everything, nodes' debug lines too (once per process; the library
    itself configures no logging)."""
    logger = logging.getLogger("otonav")
    handler = next((h for h in logger.handlers if getattr(h, _MARK, False)), None)
    if handler is None:
        handler = _StderrHandler()
        handler.setFormatter(OneLineFormatter())
        setattr(handler, _MARK, True)
        logger.addHandler(handler)
        logger.propagate = False
    handler.setLevel(logging.DEBUG if verbose else logging.WARNING)
    logger.setLevel(logging.DEBUG if verbose else logging.NOTSET)
    nodes = logging.getLogger(_NODES)
    nodes.setLevel(logging.DEBUG if verbose else logging.NOTSET)
    # The console is the command's: a sweep worker made in this process earlier (a test's,
    # or Ray's in-process actor) silenced the nodes' lines for its runs.
    nodes.propagate = True
    for quiet in [h for h in nodes.handlers if isinstance(h, logging.NullHandler)]:
        nodes.removeHandler(quiet)
