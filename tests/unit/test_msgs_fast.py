"""Message.fast builds the same frozen object as validated construction."""

from __future__ import annotations

import pydantic
import pytest

import otonav.msgs as msgs
from otonav.msgs import Header, Message, Odometry, Time

pytestmark = pytest.mark.unit

ALL = sorted((getattr(msgs, n) for n in msgs.__all__ if n != "Message"), key=lambda c: c.__name__)


@pytest.mark.parametrize("cls", ALL, ids=lambda c: c.__name__)
def test_fast_equals_validated_construction(cls: type[Message]) -> None:
    validated = cls()
    fast = cls.fast(**dict(validated.__dict__))
    assert fast == validated
    assert fast.model_dump() == validated.model_dump()
    assert fast.model_fields_set == set(cls.model_fields)


def test_fast_messages_stay_frozen() -> None:
    odom = Odometry.fast(**dict(Odometry().__dict__))
    with pytest.raises(pydantic.ValidationError, match="frozen"):
        odom.child_frame_id = "x"  # type: ignore[misc]


def test_time_from_seconds_is_exact_on_tick_instants() -> None:
    assert Time.from_seconds(11.21) == Time(sec=11, nanosec=210_000_000)
    assert Header.fast(stamp=Time.from_seconds(0.002), frame_id="odom").stamp.nanosec == 2_000_000
