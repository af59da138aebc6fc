"""Our CDR bytes are Cyclone's: for each type the bridge carries, Cyclone's own XCDR1
serializer, given the sample its deserializer read from our bytes, writes the same bytes
back (and the IDL type carries ROS 2's name). In-process, no network."""

from __future__ import annotations

import pytest

pytest.importorskip("cyclonedds")

from otonav.msgs import Clock, Imu, LaserScan, Log, Message, Odometry, PoseStamped, TFMessage
from otonav.record.cdr import encode
from otonav.ros2._dds import idl_type
from otonav.ros2._naming import dds_type_name

pytestmark = pytest.mark.unit

SAMPLES: tuple[Message, ...] = (
    Odometry.model_validate(
        {
            "header": {"stamp": {"sec": 3, "nanosec": 5}, "frame_id": "odom"},
            "child_frame_id": "base_link",
            "pose": {"pose": {"position": {"x": 1.5, "y": -2.0}}, "covariance": [0.1] * 36},
        }
    ),
    PoseStamped.model_validate({"header": {"frame_id": "map"}, "pose": {"position": {"x": 1}}}),
    LaserScan.model_validate({"header": {"frame_id": "laser"}, "ranges": [1.0, 2.5, 3.0]}),
    TFMessage.model_validate(
        {"transforms": [{"child_frame_id": "base_link", "header": {"frame_id": "odom"}}]}
    ),
    Clock.model_validate({"clock": {"sec": 12, "nanosec": 7}}),
    Imu(),
    Log.model_validate({"level": 20, "name": "nav", "msg": "hello"}),
)


@pytest.mark.parametrize("message", SAMPLES, ids=lambda m: type(m).__name__)
def test_cyclone_reads_and_writes_our_cdr_bytes(message: Message) -> None:
    kind = idl_type(type(message))
    assert kind.__idl_typename__.replace(".", "::") == dds_type_name(type(message))
    ours = encode(message)
    sample = kind.deserialize(ours)
    theirs = sample.serialize(use_version_2=False)
    assert theirs == ours + bytes(len(theirs) - len(ours))  # Cyclone pads to 4 bytes
