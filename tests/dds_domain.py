"""A DDS domain of this test's own (issue 43): concurrent gates on this machine never meet.

Each domain is held by an exclusive lock on a file in the system's temporary folder for
as long as the test uses it, so two tests (of one gate or of two) never get the same
domain, whatever their process ids.
"""

from __future__ import annotations

import fcntl
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

FIRST, LAST = 30, 101
"""Domains whose RTPS ports stay below Linux's ephemeral range (the ROS 2 docs' safe
range), away from 0, which a developer's own ROS 2 uses."""


@contextmanager
def exclusive_domain() -> Iterator[int]:
    """A ROS 2 domain id in [30, 101] that no other test holds while the block runs."""
    for domain in range(FIRST, LAST + 1):
        path = Path(tempfile.gettempdir()) / f"otonav-test-dds-domain-{domain}.lock"
        handle = path.open("a")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.close()
            continue
        try:
            yield domain
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)
            handle.close()
        return
    raise RuntimeError(f"every DDS domain {FIRST}..{LAST} is held by another test")
