"""The odometry history's cheap freshness read (the safety layer's idle path)."""

from __future__ import annotations

import pytest

from otonav.actors._bridge import ODOM
from otonav.actors._odom_history import OdomHistory
from otonav.msgs._flat import is_flat

pytestmark = pytest.mark.unit


def test_latest_stamp_is_the_newest_stamp_and_builds_nothing() -> None:
    history = OdomHistory(4)
    assert history.latest_stamp is None
    messages = [ODOM(k, 250_000_000, 0.1 * k, 0.0, 0.0, 1.0, 0.2, 0.0) for k in range(6)]
    history.extend(messages)
    assert history.latest_stamp == 5.25
    latest = history.latest
    assert latest is not None
    assert history.latest_stamp == latest[0]
    assert all(is_flat(m) for m in messages)  # read through the layout, never built
