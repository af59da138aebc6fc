"""Message.fast builds the same frozen object as validated construction."""

from __future__ import annotations

import pydantic
import pytest

import otonav.msgs as msgs
from otonav.msgs import Header, Message, Odometry, Time

pytestmark = pytest.mark.unit

ALL = sorted((getattr(msgs, n) for n in msgs.__all__ if n != "Message"), key=lambda c: c.__name__)


def _sample(cls: type[Message]) -> Message:
    """A validated instance with a non-default value in every scalar field."""
    values: dict[str, object] = {}
    for i, (name, field) in enumerate(cls.model_fields.items()):
        kind = field.annotation
        if kind in (float, "float"):
            values[name] = 1.5 + i
        elif kind in (int, "int"):
            values[name] = 7 + i
        elif kind in (str, "str"):
            values[name] = f"v{i}"
        elif kind in (bool, "bool"):
            values[name] = True
    return cls(**values)


@pytest.mark.parametrize("cls", ALL, ids=lambda c: c.__name__)
def test_fast_equals_validated_construction(cls: type[Message]) -> None:
    validated = _sample(cls)
    fast = cls.fast(**dict(validated.__dict__))
    assert fast == validated
    assert fast.model_dump() == validated.model_dump()
    assert fast.model_fields_set == set(cls.model_fields)
    # And it is not the defaults (the comparison above could not tell them apart).
    if any(
        f.annotation in (float, int, str, bool, "float", "int", "str", "bool")
        for f in cls.model_fields.values()
    ):
        assert fast != cls()


def test_fast_messages_stay_frozen() -> None:
    odom = Odometry.fast(**dict(Odometry().__dict__))
    with pytest.raises(pydantic.ValidationError, match="frozen"):
        odom.child_frame_id = "x"  # type: ignore[misc]


def test_time_from_seconds_is_exact_on_tick_instants() -> None:
    assert Time.from_seconds(11.21) == Time(sec=11, nanosec=210_000_000)
    assert Header.fast(stamp=Time.from_seconds(0.002), frame_id="odom").stamp.nanosec == 2_000_000
