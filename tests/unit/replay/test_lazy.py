"""Lazily decoded replay inputs are, from their first use on, the decoded message."""

from __future__ import annotations

import copy
import pickle
from collections.abc import Callable
from typing import Any

import pytest

from otonav.actors._bridge import ODOM as ODOM_LAYOUT
from otonav.msgs import (
    Header,
    Imu,
    LaserScan,
    Message,
    Odometry,
    Point,
    Pose,
    PoseStamped,
    PoseWithCovariance,
    Time,
    Twist,
    Vector3,
)
from otonav.msgs._flat import flat_state, is_flat
from otonav.record.cdr import decode, encode
from otonav.replay._feed import FLAT_LAYOUTS
from otonav.replay._lazy import input_maker, is_lazy, lazy, materialize
from otonav.runtime import QoS, Reliability, TopicTypeError
from otonav.runtime._mailbox import Bus, Endpoint

pytestmark = pytest.mark.unit

ODOM = Odometry(
    header=Header(stamp=Time(sec=3, nanosec=250_000_000), frame_id="odom"),
    child_frame_id="base_link",
    pose=PoseWithCovariance(pose=Pose.model_validate({"position": {"x": 1.5, "y": -2.0}})),
)
SCAN = LaserScan(ranges=(1.0, float("inf"), 0.25), range_max=8.0)


@pytest.mark.parametrize("message", [ODOM, SCAN, Twist(angular=Vector3(z=0.5))])
def test_every_operation_sees_the_decoded_message(message: Odometry | LaserScan | Twist) -> None:
    data = encode(message)
    decoded = decode(type(message), data)
    operations: dict[str, Callable[[Any], object]] = {
        "field": lambda m: getattr(m, list(type(message).model_fields)[-1]),
        "eq": lambda m: m == decoded,
        "reflected eq": lambda m: decoded == m,
        "hash": hash,
        "repr": repr,
        "str": str,
        "model_dump": lambda m: m.model_dump(),
        "copy": lambda m: copy.copy(m) == decoded,
        "deepcopy": lambda m: copy.deepcopy(m) == decoded,
        "pickle": lambda m: pickle.loads(pickle.dumps(m)) == decoded,
        "encode": encode,
        "__class__": lambda m: m.__class__,
    }
    for name, operation in operations.items():
        m = lazy(type(message), data)
        assert is_lazy(m), name
        assert isinstance(m, type(message))
        assert operation(m) == operation(decoded), name
        assert not is_lazy(m), name
        assert type(m) is type(message), name
        assert m == decoded, name
        assert m.__dict__ == decoded.__dict__, name


def test_a_stamped_message_reads_its_header_alone() -> None:
    data = encode(ODOM)
    for message in (lazy(Odometry, data), lazy(LaserScan, encode(SCAN))):
        header = message.header
        assert header == decode(type(message), encode(materialize(message))).header
    m = lazy(Odometry, data)
    header = m.header
    assert header == ODOM.header
    assert type(header) is Header
    assert is_lazy(m)  # the rest is still in CDR
    assert m.header is header
    assert m.pose == ODOM.pose  # any other use decodes the message
    assert not is_lazy(m)
    assert m.header is header  # the object handed out is the message's own
    assert m == ODOM
    assert m.__dict__ == decode(Odometry, data).__dict__
    # A message that does not start with a header is decoded whole.
    twist = lazy(Twist, encode(Twist(linear=Vector3(x=1.0))))
    assert twist.linear.x == 1.0
    assert not is_lazy(twist)


def test_a_copy_made_before_use_is_the_message_too() -> None:
    original = lazy(Odometry, encode(ODOM))
    twin = copy.copy(original)  # pydantic copies with type(self), read before decoding
    assert twin == ODOM
    assert type(twin) is Odometry


def test_bad_bytes_fail_at_first_use_with_the_type_named() -> None:
    m = lazy(Odometry, b"\x00\x01\x00\x00\x01")
    with pytest.raises(ValueError, match="cannot decode nav_msgs/msg/Odometry"):
        _ = m.header


def test_materialize_is_idempotent_and_leaves_decoded_messages_alone() -> None:
    m = lazy(Twist, encode(Twist(linear=Vector3(x=2.0))))
    assert materialize(m) is m
    assert materialize(m).linear.x == 2.0
    assert materialize(ODOM) is ODOM


@pytest.mark.asyncio
async def test_a_relayed_unread_input_passes_the_publishers_type_check() -> None:
    bus = Bus()
    publisher = bus.publisher("/cmd", Twist, endpoint=Endpoint("relay", "out"))
    inbox = bus.subscribe(
        "/cmd", Twist, QoS(Reliability.RELIABLE, depth=4), endpoint=Endpoint("b", "in")
    )
    unread = lazy(Twist, encode(Twist(linear=Vector3(x=0.3))))
    await publisher.publish(unread)
    received = inbox.try_recv()
    assert type(received) is Twist
    assert received == Twist(linear=Vector3(x=0.3))
    # A wrong type is still refused.
    with pytest.raises(TopicTypeError):
        await publisher.publish(lazy(Vector3, encode(Vector3(x=1.0))))  # type: ignore[arg-type]


@pytest.mark.parametrize("frame", ["", "a", "ab", "abc", "odom", "laser_frame", "激光雷达"])
@pytest.mark.parametrize("kind", [Odometry, LaserScan, Imu, PoseStamped])
def test_a_message_decoded_after_its_header_is_the_same(frame: str, kind: type[Message]) -> None:
    # Frame ids of every length mod 4: what follows the header starts at every alignment.
    header = Header(stamp=Time(sec=7, nanosec=123), frame_id=frame)
    fields: dict[str, object] = {"header": header}
    if kind is LaserScan:
        fields |= {"ranges": (1.0, 2.5), "intensities": (0.5,), "angle_min": -1.0}
    message = kind.model_validate(fields)
    data = encode(message)
    alone = decode(Header, data)
    assert alone == header
    after = decode(kind, data, alone)
    assert after == decode(kind, data) == message
    assert after.header is alone  # type: ignore[attr-defined]
    assert encode(after) == data


def test_inputs_of_a_fixed_layout_are_fed_as_its_flat_messages() -> None:
    make = input_maker(Odometry, FLAT_LAYOUTS)
    values = (12, 340_000_000, 1.25, -0.5, 0.2, 0.98, 0.3, -0.1)
    published = ODOM_LAYOUT(*values)  # what the bridge publishes
    data = encode(published)
    fed = make(data)
    assert is_flat(fed)
    assert flat_state(fed) == (ODOM_LAYOUT, values)
    assert fed == decode(Odometry, data)
    assert encode(fed) == data
    # Bytes that are not the template's with values in place: decoded, lazily.
    decoded = decode(Odometry, data)
    for changed in (
        decoded.model_copy(update={"child_frame_id": "base_footprint"}),
        decoded.model_copy(update={"header": Header(stamp=Time(sec=12), frame_id="map")}),
        decoded.model_copy(
            update={"pose": PoseWithCovariance(pose=decoded.pose.pose, covariance=(0.0,) * 36)}
        ),
    ):
        other = make(encode(changed))
        assert not is_flat(other)
        assert is_lazy(other)
        assert other == changed
    # -0.0 where the template has 0.0 (position.z) is another byte: not the layout's.
    z = decoded.model_copy(
        update={
            "pose": decoded.pose.model_copy(
                update={
                    "pose": decoded.pose.pose.model_copy(
                        update={"position": Point(x=1.25, y=-0.5, z=-0.0)}
                    )
                }
            )
        }
    )
    assert is_lazy(make(encode(z)))
    # A type with no layout is fed lazily.
    assert is_lazy(input_maker(LaserScan, FLAT_LAYOUTS)(encode(SCAN)))
