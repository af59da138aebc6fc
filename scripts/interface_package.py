"""The ``.msg`` files of the ROS 2 interface package ``otonav_msgs`` (``otonav_msgs/msg``
at the repository root), written from the same layouts as the recordings' schemas.

A ROS 2 user builds that package (``colcon build``) to use otonav's own types in their
nodes; the gate checks that each file equals the top-level text of the schema otonav
writes into recordings, so the two cannot drift. After changing one of these types:

    python scripts/interface_package.py otonav_msgs/msg
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Final

from otonav.msgs import (
    HardwareStatus,
    Message,
    NavDiagnostics,
    NavState,
    SafetyState,
    ScenarioVerdict,
    WheelCommand,
)
from otonav.record._schemas import schema_for

__all__ = ("PACKAGE", "TYPES", "msg_files", "msg_text")

PACKAGE: Final = "otonav_msgs"
TYPES: Final[tuple[type[Message], ...]] = (
    HardwareStatus,
    NavDiagnostics,
    NavState,
    SafetyState,
    ScenarioVerdict,
    WheelCommand,
)
"""Every message type of the package, by name."""

_DELIMITER: Final = "\n" + "=" * 80 + "\n"


def msg_text(message: type[Message]) -> str:
    """The ``.msg`` text of ``message``: its schema's top-level part (dependencies are
    other packages' files)."""
    return schema_for(message)[1].split(_DELIMITER, 1)[0]


def msg_files() -> dict[str, str]:
    """File name (``NavState.msg``) -> text, for every type of the package."""
    return {f"{t.ros_type.rsplit('/', 1)[1]}.msg": msg_text(t) for t in TYPES}


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print("usage: python scripts/interface_package.py DIR", file=sys.stderr)
        return 2
    folder = Path(argv[0])
    folder.mkdir(parents=True, exist_ok=True)
    for name, text in msg_files().items():
        (folder / name).write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
