"""A full disk (issue 27 item 5): the error every writer of artifacts raises when the
file system has no room (``ENOSPC``), the quota is used up (``EDQUOT``) or the file may
grow no more (``EFBIG``, e.g. ``ulimit -f``), and what the CLI says about it.

The CLI prints one line naming the path and exits :data:`DISK_FULL_EXIT`, distinct from
a failed run (1) and a usage error (2): the run was stopped, not judged.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

from otonav.errors import OtonavError

__all__ = ["DISK_FULL_ERRNOS", "DISK_FULL_EXIT", "DiskFullError", "is_disk_full"]

DISK_FULL_EXIT = 4
"""The exit code of a command stopped by a full disk (``otonav --help`` lists it)."""

DISK_FULL_ERRNOS = frozenset(
    code for code in (errno.ENOSPC, getattr(errno, "EDQUOT", None), errno.EFBIG) if code
)


def is_disk_full(exc: BaseException) -> bool:
    """``exc`` says there is no room to write (disk, quota or file size limit)."""
    return isinstance(exc, OSError) and exc.errno in DISK_FULL_ERRNOS


class DiskFullError(OtonavError):
    """No room to write ``path``; ``detail`` says what was kept and what to do."""

    def __init__(self, path: str | Path, cause: OSError, detail: str = "") -> None:
        self.path = Path(path)
        self.cause = cause
        self.detail = detail
        reason = os.strerror(cause.errno) if cause.errno else str(cause)
        super().__init__(f"{self.path}: {reason.lower()}" + (f"; {detail}" if detail else ""))

    def with_detail(self, detail: str) -> DiskFullError:
        """The same error, saying ``detail`` (what was kept, where to go next)."""
        return DiskFullError(self.path, self.cause, detail)
