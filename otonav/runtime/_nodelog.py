"""``self.log``: an actor's logger, as rclpy's ``self.get_logger()`` (ADR 0070).

    self.log.info("goal %s reached", goal)
    self.log.warning("scan is %.1f s old", age)

Each line goes two ways: to the Python logger ``otonav.node`` (the CLI prints warnings
and errors as they happen, everything with ``-v``; pytest captures them), and, at INFO
and above, to the actor's sink, which the stack sets to publish ``/rosout``
(``rcl_interfaces/msg/Log``, stamped in sim time, named by the actor), so the recording
keeps them. The levels are rclpy's and Python's (DEBUG 10 ... FATAL 50).
"""

from __future__ import annotations

import logging
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, Final, Protocol

if TYPE_CHECKING:
    from otonav.runtime._clock import Clock


class _Node(Protocol):
    """What a logger needs of its actor (:class:`~otonav.runtime._actor.Actor`)."""

    @property
    def name(self) -> str: ...

    @property
    def _otonav_clock(self) -> Clock | None: ...


__all__ = ["LOGGER_NAME", "LogSink", "NodeLogger"]

LOGGER_NAME: Final = "otonav.node"
_python_log = logging.getLogger(LOGGER_NAME)

LogSink = Callable[[float, int, str, str, str, str, int], None]
"""``(sim_time, level, actor, text, file, function, line)``: where a line goes besides
the Python logger (the stack's /rosout publisher)."""


class NodeLogger:
    """An actor's logger: ``debug``, ``info``, ``warning`` (``warn``), ``error``,
    ``fatal``, each ``(msg, *args)`` with ``%`` formatting as :mod:`logging` has it."""

    __slots__ = ("_actor", "sink")

    def __init__(self, actor: _Node) -> None:
        self._actor = actor
        self.sink: LogSink | None = None

    def log(self, level: int, msg: object, *args: object) -> None:
        """Log ``msg % args`` at ``level`` (10 debug ... 50 fatal)."""
        self._emit(level, msg, args)

    def _emit(self, level: int, msg: object, args: tuple[object, ...]) -> None:
        sink = self.sink if level >= logging.INFO else None
        if sink is None and not _python_log.isEnabledFor(level):
            return
        text = str(msg) % args if args else str(msg)
        clock = self._actor._otonav_clock
        now = clock.now() if clock is not None else 0.0
        name = self._actor.name
        caller = sys._getframe(2)
        if sink is not None:
            code = caller.f_code
            sink(now, level, name, text, code.co_filename, code.co_name, caller.f_lineno)
        extra: dict[str, Any] = {"otonav_node": name, "sim_time": now}
        _python_log.log(level, "%s", text, extra=extra, stacklevel=3)

    def debug(self, msg: object, *args: object) -> None:
        self._emit(logging.DEBUG, msg, args)

    def info(self, msg: object, *args: object) -> None:
        self._emit(logging.INFO, msg, args)

    def warning(self, msg: object, *args: object) -> None:
        self._emit(logging.WARNING, msg, args)

    warn = warning

    def error(self, msg: object, *args: object) -> None:
        self._emit(logging.ERROR, msg, args)

    def fatal(self, msg: object, *args: object) -> None:
        self._emit(logging.CRITICAL, msg, args)
