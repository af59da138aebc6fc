"""Quality of service, with ROS 2's matching rules.

A publisher and a subscriber connect only when the publisher offers at least what the
subscriber requests: a reliable subscriber needs a reliable publisher, and a
transient-local subscriber needs a transient-local publisher. ROS 2 leaves such a
pair silently unconnected; here it is an error at wiring time.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum


class Reliability(StrEnum):
    """Whether a mailbox may lose messages (best-effort) or applies backpressure (reliable)."""

    RELIABLE = "reliable"
    BEST_EFFORT = "best_effort"


class Durability(StrEnum):
    """Whether a late subscriber gets the publisher's last ``depth`` messages."""

    VOLATILE = "volatile"
    TRANSIENT_LOCAL = "transient_local"


MAX_DEPTH = 1_000_000
"""Keep-last N at most a million: a mailbox may hold ``depth`` messages, and a million
360-beam scans is 1.4 GB."""


@dataclass(frozen=True, slots=True)
class QoS:
    """A QoS profile: reliability, history depth (keep-last N) and durability."""

    reliability: Reliability = Reliability.RELIABLE
    depth: int = 10
    durability: Durability = Durability.VOLATILE

    def __post_init__(self) -> None:
        # Checked here, not where the profile is first used: a plain string or a
        # fractional depth used to pass and break graph() and the mailboxes later.
        if not isinstance(self.reliability, Reliability):
            raise TypeError(
                f"QoS reliability must be a Reliability, got {self.reliability!r} "
                f"(use {' or '.join(f'Reliability.{r.name}' for r in Reliability)})"
            )
        if not isinstance(self.durability, Durability):
            raise TypeError(
                f"QoS durability must be a Durability, got {self.durability!r} "
                f"(use {' or '.join(f'Durability.{d.name}' for d in Durability)})"
            )
        if not isinstance(self.depth, int) or isinstance(self.depth, bool):
            raise TypeError(f"QoS depth must be a whole number (keep-last N), got {self.depth!r}")
        if not 1 <= self.depth <= MAX_DEPTH:
            raise ValueError(
                f"QoS depth must be >= 1 and <= {MAX_DEPTH} (keep-last N), got {self.depth}"
            )

    def __str__(self) -> str:
        return f"{self.reliability.value}/depth={self.depth}/{self.durability.value}"


#: ROS 2's default profile: reliable, keep last 10, volatile.
DEFAULT_QOS = QoS()
#: ROS 2's sensor-data profile: best-effort, small depth, volatile.
SENSOR_DATA_QOS = QoS(Reliability.BEST_EFFORT, depth=5)
#: A "latched" topic (goals, maps, static transforms): reliable, transient-local.
LATCHED_QOS = QoS(Reliability.RELIABLE, depth=1, durability=Durability.TRANSIENT_LOCAL)


def incompatibility(offered: QoS, requested: QoS) -> str | None:
    """Why a publisher offering ``offered`` cannot serve a subscriber requesting
    ``requested``, with the fix; ``None`` when they match (ROS 2 rules)."""
    reasons: list[str] = []
    if (
        requested.reliability is Reliability.RELIABLE
        and offered.reliability is Reliability.BEST_EFFORT
    ):
        reasons.append(
            "the subscriber requests reliable delivery but the publisher only offers "
            "best_effort (fix: make the subscriber best_effort, e.g. SENSOR_DATA_QOS, "
            "or the publisher reliable)"
        )
    if (
        requested.durability is Durability.TRANSIENT_LOCAL
        and offered.durability is Durability.VOLATILE
    ):
        reasons.append(
            "the subscriber requests transient_local durability but the publisher is "
            "volatile and keeps no history (fix: make the subscriber volatile or the "
            "publisher transient_local)"
        )
    return "; ".join(reasons) or None
