"""``offered_qos_profiles``: a topic's QoS in the YAML rosbag2 writes (docs/adr/0044).

rosbag2 stores, per topic, the QoS profiles its publishers offered, so ``ros2 bag play``
offers the same again (a latched ``/tf_static`` needs transient-local there). The MCAP
``ros2`` profile makes the key required in every channel's metadata. The form is
rosbag2's metadata version 9 (ROS 2 Jazzy): a YAML list, one mapping per publisher,
enums as lower-case names and durations as ``{sec, nsec}``. otonav's QoS has no
deadline, lifespan or liveliness lease: those are "infinite", written as rmw reports an
unset duration of a live endpoint (``RMW_DURATION_INFINITE``: 9223372036 s 854775807 ns),
liveliness ``automatic``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Final

import yaml

from otonav.runtime._qos import DEFAULT_QOS, Durability, QoS, Reliability

__all__ = ("INFINITE", "offered_qos_profiles", "offered_qos_yaml", "recorded_qos")

INFINITE: Final = {"sec": 9223372036, "nsec": 854775807}
"""``RMW_DURATION_INFINITE`` as rosbag2 writes it."""


def _profile(qos: QoS) -> dict[str, Any]:
    return {
        "history": "keep_last",
        "depth": qos.depth,
        "reliability": qos.reliability.value,
        "durability": qos.durability.value,
        "deadline": dict(INFINITE),
        "lifespan": dict(INFINITE),
        "liveliness": "automatic",
        "liveliness_lease_duration": dict(INFINITE),
        "avoid_ros_namespace_conventions": False,
    }


def offered_qos_profiles(offered: Sequence[QoS]) -> list[dict[str, Any]]:
    """One rosbag2 profile per offered QoS (ROS 2's default profile when none was
    offered: a topic written by no publisher, such as the verdict)."""
    return [_profile(qos) for qos in (offered or (DEFAULT_QOS,))]


def _infinite(key: str) -> str:
    return f"  {key}:\n    sec: {INFINITE['sec']}\n    nsec: {INFINITE['nsec']}\n"


_ENTRY = (
    "- history: keep_last\n  depth: {depth}\n  reliability: {reliability}\n"
    "  durability: {durability}\n"
    + _infinite("deadline")
    + _infinite("lifespan")
    + "  liveliness: automatic\n"
    + _infinite("liveliness_lease_duration")
    + "  avoid_ros_namespace_conventions: false\n"
)
"""One profile as ``yaml.safe_dump`` writes :func:`offered_qos_profiles`' mapping (block
style, keys in order); the depth is a decimal int, the enums plain lower-case words."""


def offered_qos_yaml(offered: Sequence[QoS]) -> str:
    """:func:`offered_qos_profiles` as the YAML string of an MCAP channel's metadata:
    the text ``yaml.safe_dump(..., default_flow_style=False, sort_keys=False)`` gives,
    stripped (a test compares the two for every reliability, durability and a range of
    depths), formatted directly: the dump cost ~0.4 ms a channel, ~6 ms of a recorded
    run's 16 channels (ADR 0058)."""
    text = "".join(
        _ENTRY.format(
            depth=qos.depth, reliability=qos.reliability.value, durability=qos.durability.value
        )
        for qos in (offered or (DEFAULT_QOS,))
    )
    return text.strip()


_RELIABILITY: Final = {1: Reliability.RELIABLE, 2: Reliability.BEST_EFFORT}
_DURABILITY: Final = {1: Durability.TRANSIENT_LOCAL, 2: Durability.VOLATILE}
"""rosbag2's older integer enums (rmw's), beside the names :func:`offered_qos_yaml` writes."""


def recorded_qos(text: str) -> QoS:
    """The inverse of :func:`offered_qos_yaml`: the first profile of a channel's
    ``offered_qos_profiles`` (otonav's names or rosbag2's integers); ROS 2's default
    profile (reliable, volatile, 10) for an empty, unreadable or unknown one."""
    try:
        profiles = yaml.safe_load(text or "[]")
        first = profiles[0] if isinstance(profiles, list) and profiles else None
        if not isinstance(first, dict):
            return DEFAULT_QOS
        reliability = first.get("reliability", Reliability.RELIABLE.value)
        durability = first.get("durability", Durability.VOLATILE.value)
        depth = first.get("depth", DEFAULT_QOS.depth)
        return QoS(
            _RELIABILITY.get(reliability) or Reliability(reliability),
            depth=depth if isinstance(depth, int) and 0 < depth <= 10_000 else DEFAULT_QOS.depth,
            durability=_DURABILITY.get(durability) or Durability(durability),
        )
    except (yaml.YAMLError, ValueError, TypeError):
        return DEFAULT_QOS
