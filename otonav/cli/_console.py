"""The CLI's rich console: on a terminal, sized to it; otherwise (a pipe, a log file,
CI) lines are never hard-wrapped, so a path or a reason stays on one line to grep."""

from __future__ import annotations

from typing import Any

from rich.console import Console

__all__ = ["make_console"]

UNWRAPPED = 10_000
"""Columns of a console that is not a terminal: wide enough that nothing wraps."""


def make_console(**kwargs: Any) -> Console:
    """A console with ``kwargs`` (``width`` applies on a terminal only)."""
    console = Console(highlight=False, **kwargs)
    if console.is_terminal:
        return console
    kwargs.pop("width", None)
    return Console(highlight=False, width=UNWRAPPED, soft_wrap=True, **kwargs)
