"""Hardware health: what any HAL says about itself, whatever is under it.

Shaped like a ROS ``diagnostic_msgs/DiagnosticStatus`` (levels OK, WARN, ERROR, STALE)
plus what the robot's control loop needs: ``ready`` (the hardware takes commands) and a
short ``fault`` kind. A simulated world is always OK; a CAN interface reports starting,
faults (lost heartbeat, axis error, bus-off, ...) and recoveries. The bridge publishes
it (``/hardware/status``, ``/diagnostics``, ``/rosout``), and the base and the navigator
react to it, so nothing above the HAL knows what kind of hardware it drives.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

__all__ = ["HardwareHealth", "HealthLevel"]


class HealthLevel(enum.IntEnum):
    """``diagnostic_msgs/DiagnosticStatus`` levels."""

    OK = 0
    WARN = 1
    ERROR = 2
    STALE = 3


@dataclass(frozen=True, slots=True)
class HardwareHealth:
    """The hardware's state at sim time ``since`` (when it last changed).

    ``level`` ERROR or worse is a fault: the base must command zero. ``ready`` False
    (starting, recovering) also means zero commands, without being a fault.
    ``fault`` is a short kind (``heartbeat_lost``, ``axis_error``, ...), empty when none;
    ``message`` is one line for people, naming the part (e.g. the node id) and what to
    check. ``values`` are key/value details for ``/diagnostics``.
    """

    level: HealthLevel = HealthLevel.OK
    ready: bool = True
    fault: str = ""
    message: str = "ok"
    since: float = 0.0
    values: tuple[tuple[str, str], ...] = ()
    permanent: bool = False
    """The fault will not clear without people (recovery gave up, or a wrong node id):
    a scenario run ends on it, with the fault as its verdict's reason."""

    @property
    def faulted(self) -> bool:
        """ERROR or STALE: the hardware must not be driven."""
        return self.level >= HealthLevel.ERROR

    @property
    def drivable(self) -> bool:
        """Ready and not faulted: wheel commands may be non-zero."""
        return self.ready and not self.faulted
