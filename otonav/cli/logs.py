"""The CLI's log lines: one line per warning or error on stderr, never a traceback.

The runtime logs an actor's crash with its whole traceback (``otonav.runtime.system``);
the recording keeps that traceback on ``/rosout``. On a terminal Python's fallback
handler printed all of it (65 lines for one crash, issue 27): here each record becomes
its first line and the exception it ended with.
"""

from __future__ import annotations

import logging
import sys

_MARK = "_otonav_cli_handler"


class OneLineFormatter(logging.Formatter):
    """``otonav: [0.500] nav crashed: RuntimeError: boom (traceback on /rosout)``."""

    def format(self, record: logging.LogRecord) -> str:
        lines = [line for line in record.getMessage().splitlines() if line.strip()]
        if not lines:
            return "otonav:"
        head = lines[0].removesuffix("Traceback (most recent call last):").rstrip()
        if len(lines) == 1:
            return f"otonav: {head}"
        return f"otonav: {head}: {lines[-1].strip()} (traceback on /rosout in the recording)"


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


def install() -> None:
    """Route the ``otonav`` loggers' warnings and errors to stderr, one line each (once
    per process; the library itself configures no logging)."""
    logger = logging.getLogger("otonav")
    if any(getattr(h, _MARK, False) for h in logger.handlers):
        return
    handler = _StderrHandler()
    handler.setLevel(logging.WARNING)
    handler.setFormatter(OneLineFormatter())
    setattr(handler, _MARK, True)
    logger.addHandler(handler)
    logger.propagate = False
