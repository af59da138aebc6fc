"""Flat messages (otonav.msgs._flat) are, from their first use on, the message the bridge
used to build eagerly; before it, only ``type()`` tells them apart, and the readers
that must not build them (the odometry history, the publisher) do not."""

from __future__ import annotations

import copy
import math
import pickle
from collections.abc import Callable
from typing import Any

import pytest

from otonav.actors._bridge import CLOCK, IMU, ODOM, TF
from otonav.actors._odom_history import OdomHistory
from otonav.msgs import (
    Clock,
    Header,
    Imu,
    Odometry,
    Point,
    Pose,
    PoseWithCovariance,
    Quaternion,
    TFMessage,
    Time,
    Transform,
    TransformStamped,
    Twist,
    TwistWithCovariance,
    Vector3,
)
from otonav.msgs._flat import FlatLayout, flat_state, is_flat, materialize, reader, real_type
from otonav.record.cdr import encode
from otonav.runtime import QoS, Reliability, TopicTypeError
from otonav.runtime._mailbox import Bus, Endpoint

pytestmark = pytest.mark.unit

_POSE_COV = tuple(float(i) for i in range(36))
_TWIST_COV = tuple(-float(i) for i in range(36))


def eager_odometry(
    sec: int, nsec: int, x: float, y: float, yaw: float, v: float, w: float
) -> Odometry:
    """The /odom message as the bridge built it before fixed layouts (ADR 0027's code)."""
    from otonav.actors._bridge import _POSE_COV as pose_cov
    from otonav.actors._bridge import _TWIST_COV as twist_cov

    return Odometry.fast(
        header=Header.fast(stamp=Time.fast(sec=sec, nanosec=nsec), frame_id="odom"),
        child_frame_id="base_link",
        pose=PoseWithCovariance.fast(
            pose=Pose.fast(
                position=Point.fast(x=x, y=y, z=0.0), orientation=Quaternion.from_yaw(yaw)
            ),
            covariance=pose_cov,
        ),
        twist=TwistWithCovariance.fast(
            twist=Twist.fast(
                linear=Vector3.fast(x=v, y=0.0, z=0.0), angular=Vector3.fast(x=0.0, y=0.0, z=w)
            ),
            covariance=twist_cov,
        ),
    )


def flat_odometry(
    sec: int, nsec: int, x: float, y: float, yaw: float, v: float, w: float
) -> Odometry:
    return ODOM(sec, nsec, x, y, math.sin(yaw / 2), math.cos(yaw / 2), v, w)


ARGS = (12, 340_000_000, 1.25, -0.5, 0.7, 0.31, -0.2)


def test_a_flat_odometry_is_the_eager_one_field_for_field() -> None:
    eager = eager_odometry(*ARGS)
    flat = flat_odometry(*ARGS)
    assert is_flat(flat)
    assert isinstance(flat, Odometry)
    assert type(flat) is not Odometry  # only type() tells it apart before first use
    assert flat == eager
    assert type(flat) is Odometry
    assert not is_flat(flat)
    assert flat.model_dump() == eager.model_dump()
    assert flat.model_fields_set == eager.model_fields_set
    assert flat.pose.pose.model_fields_set == eager.pose.pose.model_fields_set
    # And it is not just any Odometry (the comparison could not tell defaults apart).
    assert flat != eager_odometry(12, 340_000_000, 1.25, -0.5, 0.7, 0.31, -0.25)


def test_the_other_streams_are_the_eager_messages() -> None:
    stamp = Time.fast(sec=3, nanosec=5)
    orientation = Quaternion.from_yaw(-2.0)
    tf = TFMessage.fast(
        transforms=(
            TransformStamped.fast(
                header=Header.fast(stamp=stamp, frame_id="odom"),
                child_frame_id="base_link",
                transform=Transform.fast(
                    translation=Vector3.fast(x=4.0, y=-1.0, z=0.0), rotation=orientation
                ),
            ),
        )
    )
    assert TF(3, 5, 4.0, -1.0, orientation.z, orientation.w) == tf
    imu = Imu.fast(
        header=Header.fast(stamp=stamp, frame_id="imu_link"),
        orientation=Quaternion.fast(x=0.1, y=0.2, z=0.3, w=0.9),
        orientation_covariance=(0.0,) * 9,
        angular_velocity=Vector3.fast(x=1.0, y=2.0, z=3.0),
        angular_velocity_covariance=(0.0,) * 9,
        linear_acceleration=Vector3.fast(x=4.0, y=5.0, z=9.81),
        linear_acceleration_covariance=(0.0,) * 9,
    )
    assert IMU(3, 5, 0.1, 0.2, 0.3, 0.9, 1.0, 2.0, 3.0, 4.0, 5.0, 9.81) == imu
    assert CLOCK(3, 5) == Clock.fast(clock=stamp)


def test_every_operation_sees_the_built_message() -> None:
    eager = eager_odometry(*ARGS)
    operations: dict[str, Callable[[Any], object]] = {
        "field": lambda m: m.header,
        "method": lambda m: m.pose.pose.orientation.yaw(),
        "eq": lambda m: m == eager,
        "reflected eq": lambda m: eager == m,
        "ne": lambda m: m != eager,
        "hash": lambda m: hash(m.header.stamp),  # frozen, hashable fields
        "repr": repr,
        "str": str,
        "model_dump": lambda m: m.model_dump(),
        "model_dump_json": lambda m: m.model_dump_json(),
        "dict": lambda m: dict(m),
        "copy": lambda m: copy.copy(m) == eager,
        "deepcopy": lambda m: copy.deepcopy(m) == eager,
        "model_copy": lambda m: m.model_copy(update={"child_frame_id": "x"}).child_frame_id,
        "pickle": lambda m: pickle.loads(pickle.dumps(m)) == eager,
        "__class__": lambda m: m.__class__,
        "__dict__": lambda m: m.__dict__,
    }
    for name, operation in operations.items():
        m = flat_odometry(*ARGS)
        assert is_flat(m), name
        assert operation(m) == operation(eager), name
        assert not is_flat(m), name
        assert type(m) is Odometry, name
        assert m == eager, name
        assert m.__dict__ == eager.__dict__, name
    # Encoding is the one use that does not build it (the recorder's).
    m = flat_odometry(*ARGS)
    assert encode(m) == encode(eager)
    assert is_flat(m)


def test_a_copy_made_before_use_is_the_message_too() -> None:
    twin = copy.copy(flat_odometry(*ARGS))
    assert twin == eager_odometry(*ARGS)
    assert type(twin) is Odometry
    assert encode(copy.copy(flat_odometry(*ARGS))) == encode(eager_odometry(*ARGS))


def test_a_pickled_flat_message_arrives_as_the_message() -> None:
    back = pickle.loads(pickle.dumps(flat_odometry(*ARGS)))
    assert type(back) is Odometry
    assert back == eager_odometry(*ARGS)


def test_flat_messages_stay_frozen() -> None:
    m = flat_odometry(*ARGS)
    with pytest.raises(Exception, match="frozen"):
        m.child_frame_id = "x"  # type: ignore[misc]


def test_materialize_is_idempotent_and_leaves_other_messages_alone() -> None:
    m = flat_odometry(*ARGS)
    assert materialize(m) is m
    assert materialize(m) is m
    eager = eager_odometry(*ARGS)
    assert materialize(eager) is eager
    assert flat_state(eager) is None
    assert real_type(type(flat_odometry(*ARGS))) is Odometry
    assert real_type(Odometry) is Odometry


def test_the_reader_gives_the_attributes_values_without_building() -> None:
    read = reader(
        Odometry,
        "header.stamp.sec",
        "pose.pose.position.x",
        "pose.pose.orientation.w",
        "pose.pose.position.z",  # a constant of the template
        "child_frame_id",
        "pose.covariance",
    )
    flat, eager = flat_odometry(*ARGS), eager_odometry(*ARGS)
    assert read(flat) == read(eager)
    assert read(flat)[:2] == (12, 1.25)
    assert is_flat(flat)
    one = reader(Odometry, "twist.twist.angular.z")
    assert one(flat) == one(eager) == (-0.2,)
    assert is_flat(flat)
    with pytest.raises(ValueError, match="at least one path"):
        reader(Odometry)


def test_the_odometry_history_reads_flat_messages_without_building_them() -> None:
    flats, eagers = OdomHistory(8), OdomHistory(8)
    messages = []
    for k in range(12):
        args = (k, 500_000_000 * (k % 2), 0.1 * k, -0.05 * k, 0.3 * k - 1.0, 0.2, 0.01 * k)
        messages.append(flat_odometry(*args))
        flats.extend([messages[-1]])
        eagers.extend([eager_odometry(*args)])
    assert flats.latest == eagers.latest
    assert flats.latest is not None
    assert flats.latest[0] == 11.5
    for stamp in (0.0, 5.2, 7.74, 9.0, 11.5, 30.0):
        assert flats.pose_at(stamp) == eagers.pose_at(stamp)
    assert all(is_flat(m) for m in messages)


@pytest.mark.asyncio
async def test_a_publisher_takes_a_flat_message_as_it_is() -> None:
    bus = Bus()
    publisher = bus.publisher("/odom", Odometry, endpoint=Endpoint("bridge", "odom"))
    inbox = bus.subscribe(
        "/odom", Odometry, QoS(Reliability.RELIABLE, depth=4), endpoint=Endpoint("b", "in")
    )
    for _ in range(2):  # the first passes the slow check, the second the remembered one
        await publisher.publish(flat_odometry(*ARGS))
        received = inbox.try_recv()
        assert is_flat(received)
        assert received == eager_odometry(*ARGS)
    # A flat message of another type is still refused.
    wrong = bus.publisher("/clock2", Odometry, endpoint=Endpoint("x", "clock"))
    with pytest.raises(TopicTypeError):
        await wrong.publish(CLOCK(1, 2))  # type: ignore[arg-type]


def test_bad_layouts_are_refused_with_the_path_named() -> None:
    template = eager_odometry(*ARGS)
    with pytest.raises(ValueError, match="'child_frame_id' is a str"):
        FlatLayout(template, ("child_frame_id",))
    with pytest.raises(ValueError, match="has no field 'stomp'"):
        FlatLayout(template, ("header.stomp.sec",))
    with pytest.raises(ValueError, match="given twice"):
        FlatLayout(template, ("header.stamp.sec", "header.stamp.sec"))
    with pytest.raises(ValueError, match=r"inside 'header\.stamp\.sec'"):
        FlatLayout(template, ("header.stamp.sec", "header.stamp.sec.x"))
    with pytest.raises(ValueError, match=r"'header\.stamp' is a Time"):
        FlatLayout(template, ("header.stamp",))
    with pytest.raises(ValueError, match="no element '1' of 1"):
        FlatLayout(TF.template, ("transforms.1.header.stamp.sec",))
    with pytest.raises(TypeError, match="ordinary message"):
        FlatLayout(flat_odometry(*ARGS), ("header.stamp.sec",))


def test_a_reader_path_holding_varying_values_reads_them_not_the_template() -> None:
    # header.stamp of a layout that varies header.stamp.sec: the template's Time would
    # be wrong, so the reader reads the built message (the same values either way).
    read = reader(Odometry, "header.stamp", "pose.pose.position", "child_frame_id")
    flat, eager = flat_odometry(*ARGS), eager_odometry(*ARGS)
    assert read(flat) == read(eager)
    assert read(flat)[0] == Time.fast(sec=12, nanosec=340_000_000)
    # A path inside a varying value fails as it does on the message itself.
    inside = reader(Odometry, "header.stamp.sec.real")
    assert inside(flat_odometry(*ARGS)) == inside(eager) == (12,)
