"""A QoS profile is checked when it is built: a plain string or a fractional depth used
to be accepted and broke ``graph()`` and the mailboxes later (issue 17, item 6)."""

from __future__ import annotations

from typing import Any

import pytest

from otonav.runtime import QoS, Reliability, System
from otonav.runtime._qos import Durability

pytestmark = pytest.mark.unit


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"reliability": "reliable"}, "reliability must be a Reliability"),
        ({"reliability": "best_effort"}, "Reliability.BEST_EFFORT"),
        ({"durability": "transient_local"}, "durability must be a Durability"),
        ({"depth": 2.5}, "depth must be a whole number"),
        ({"depth": "10"}, "depth must be a whole number"),
        ({"depth": True}, "depth must be a whole number"),
        ({"depth": 0}, "depth must be >= 1 and <= 1000000"),
        ({"depth": 10**9}, "<= 1000000 (keep-last N), got 1000000000"),
    ],
)
def test_invalid_qos_is_refused_at_construction(kwargs: dict[str, Any], fragment: str) -> None:
    with pytest.raises((TypeError, ValueError)) as err:
        QoS(**kwargs)
    assert fragment in str(err.value)


def test_a_valid_qos_still_shows_in_the_graph() -> None:
    qos = QoS(Reliability.BEST_EFFORT, depth=3, durability=Durability.VOLATILE)
    system = System([])
    system.subscribe("/x", int, qos)
    (topic,) = system.graph().topics
    assert str(topic.subscriptions[0].qos) == "best_effort/depth=3/volatile"
