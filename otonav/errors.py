"""The base of every error otonav raises on purpose, and the one kind a user's input
causes: a :class:`UsageError` is one line naming the file, flag or key and what would be
valid; the CLI prints it and exits 2, with no traceback."""

from __future__ import annotations

__all__ = ["OtonavError", "UsageError"]


class OtonavError(Exception):
    """Base class of every error otonav raises on purpose."""


class UsageError(OtonavError, ValueError):
    """Bad input (a config key, a file, a flag): one line saying what and what is valid."""
