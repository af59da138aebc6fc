# mypy: disable-error-code="call-arg"
"""A ROS 2 node's view of otonav, on plain cyclonedds, in its own process (no otonav import).

The types are written out by hand as ROS 2's generated IDL has them (module
``nav_msgs::msg::dds_``, struct ``Odometry_``), so the DDS type names, the field layout
and the CDR bytes are checked against a second, independent definition: Cyclone's own
serializer and deserializer. The participant is configured as rmw_cyclonedds configures
a node with ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``.

    python ros2_peer.py DOMAIN GOAL_X GOAL_Y TIMEOUT_S

Subscribes to rt/odom, rt/scan, rt/tf and rt/clock; once the bridge's goal reader is
matched, publishes a goal on rt/goal (reliable, volatile: ``ros2 topic pub``'s offer);
reads /odom until the robot is within 0.15 m of it, then prints one JSON line.
"""

# No ``from __future__ import annotations``: cyclonedds reads the field annotations.
import json
import math
import signal
import sys
import time
from dataclasses import dataclass, field

from cyclonedds.core import InstanceState, ReadCondition, SampleState, ViewState, WaitSet
from cyclonedds.domain import Domain, DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl import types as t
from cyclonedds.pub import DataWriter
from cyclonedds.qos import Policy, Qos
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

# On loopback, as the bridge: Cyclone 11 (this package; ROS 2's rmw_cyclonedds ships 0.10,
# which has no such rule) drops discovery arriving on an interface it did not select, and
# selects eth0, so whether the two met depended on which one heard the other first.
LOCALHOST = (
    "<CycloneDDS><Domain><General><AllowMulticast>false</AllowMulticast>"
    '<Interfaces><NetworkInterface name="lo"/></Interfaces></General>'
    "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
    "<MaxAutoParticipantIndex>32</MaxAutoParticipantIndex>"
    '<Peers><Peer address="localhost"/></Peers></Discovery></Domain></CycloneDDS>'
)


@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: t.int32 = 0
    nanosec: t.uint32 = 0


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time = field(default_factory=Time)
    frame_id: str = ""


@dataclass
class Point(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
    x: t.float64 = 0.0
    y: t.float64 = 0.0
    z: t.float64 = 0.0


@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: t.float64 = 0.0
    y: t.float64 = 0.0
    z: t.float64 = 0.0


@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: t.float64 = 0.0
    y: t.float64 = 0.0
    z: t.float64 = 0.0
    w: t.float64 = 1.0


@dataclass
class Pose(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
    position: Point = field(default_factory=Point)
    orientation: Quaternion = field(default_factory=Quaternion)


@dataclass
class PoseWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovariance_"):
    pose: Pose = field(default_factory=Pose)
    covariance: t.array[t.float64, 36] = field(default_factory=lambda: [0.0] * 36)


@dataclass
class Twist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    linear: Vector3 = field(default_factory=Vector3)
    angular: Vector3 = field(default_factory=Vector3)


@dataclass
class TwistWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::TwistWithCovariance_"):
    twist: Twist = field(default_factory=Twist)
    covariance: t.array[t.float64, 36] = field(default_factory=lambda: [0.0] * 36)


@dataclass
class Odometry(IdlStruct, typename="nav_msgs::msg::dds_::Odometry_"):
    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    pose: PoseWithCovariance = field(default_factory=PoseWithCovariance)
    twist: TwistWithCovariance = field(default_factory=TwistWithCovariance)


@dataclass
class PoseStamped(IdlStruct, typename="geometry_msgs::msg::dds_::PoseStamped_"):
    header: Header = field(default_factory=Header)
    pose: Pose = field(default_factory=Pose)


@dataclass
class Transform(IdlStruct, typename="geometry_msgs::msg::dds_::Transform_"):
    translation: Vector3 = field(default_factory=Vector3)
    rotation: Quaternion = field(default_factory=Quaternion)


@dataclass
class TransformStamped(IdlStruct, typename="geometry_msgs::msg::dds_::TransformStamped_"):
    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    transform: Transform = field(default_factory=Transform)


@dataclass
class TFMessage(IdlStruct, typename="tf2_msgs::msg::dds_::TFMessage_"):
    transforms: t.sequence[TransformStamped] = field(default_factory=list)


@dataclass
class LaserScan(IdlStruct, typename="sensor_msgs::msg::dds_::LaserScan_"):
    header: Header = field(default_factory=Header)
    angle_min: t.float32 = 0.0
    angle_max: t.float32 = 0.0
    angle_increment: t.float32 = 0.0
    time_increment: t.float32 = 0.0
    scan_time: t.float32 = 0.0
    range_min: t.float32 = 0.0
    range_max: t.float32 = 0.0
    ranges: t.sequence[t.float32] = field(default_factory=list)
    intensities: t.sequence[t.float32] = field(default_factory=list)


@dataclass
class Clock(IdlStruct, typename="rosgraph_msgs::msg::dds_::Clock_"):
    clock: Time = field(default_factory=Time)


XCDR1 = Policy.DataRepresentation(use_cdrv0_representation=True)
ANY = Qos(Policy.Reliability.BestEffort, Policy.History.KeepLast(10), XCDR1)
GOAL_QOS = Qos(Policy.Reliability.Reliable(10**9), Policy.History.KeepLast(1), XCDR1)


WAKE = duration(milliseconds=50)
"""The longest the peer blocks on its readers before it looks for a goal reader again."""


def main() -> None:
    domain, gx, gy, timeout = int(sys.argv[1]), *map(float, sys.argv[2:5])
    _domain = Domain(domain, LOCALHOST)
    dp = DomainParticipant(domain)
    readers = {
        name: DataReader(dp, Topic(dp, f"rt/{name}", kind), qos=ANY)
        for name, kind in (("odom", Odometry), ("scan", LaserScan), ("tf", TFMessage))
    }
    readers["clock"] = DataReader(dp, Topic(dp, "rt/clock", Clock), qos=ANY)
    goal_writer = DataWriter(dp, Topic(dp, "rt/goal", PoseStamped), qos=GOAL_QOS)
    # Block on the readers (a DDS wait set), not on the wall clock: woken when a sample
    # arrives, or after WAKE to look for the bridge's goal reader.
    arrivals = WaitSet(dp)
    for reader in readers.values():
        mask = SampleState.NotRead | ViewState.Any | InstanceState.Any
        arrivals.attach(ReadCondition(reader, mask))
    counts = dict.fromkeys(readers, 0)
    report: dict[str, object] = {"reached": False, "sent_goal": False}
    latencies: list[float] = []
    stop = [time.monotonic() + timeout]
    signal.signal(signal.SIGTERM, lambda *_: stop.__setitem__(0, 0.0))  # report, then exit
    while time.monotonic() < stop[0]:
        if not report["sent_goal"] and goal_writer.get_matched_subscriptions():
            goal = PoseStamped(Header(Time(0, 0), "odom"), Pose(Point(gx, gy, 0.0)))
            goal_writer.write(goal)
            report["sent_goal"] = True
        for name, reader in readers.items():
            for sample in reader.take(N=100):
                if not sample.sample_info.valid_data:
                    continue  # a writer went away (the bridge closed): no data
                counts[name] += 1
                if name == "odom":
                    now = time.time_ns()
                    latencies.append((now - sample.sample_info.source_timestamp) / 1e6)
                    position = sample.pose.pose.position
                    report["odom"] = {
                        "x": position.x,
                        "y": position.y,
                        "frame_id": sample.header.frame_id,
                        "child_frame_id": sample.child_frame_id,
                        "stamp": sample.header.stamp.sec + sample.header.stamp.nanosec * 1e-9,
                    }
                    if math.hypot(position.x - gx, position.y - gy) < 0.15:
                        report["reached"] = True
                elif name == "scan":
                    report["scan_beams"] = len(sample.ranges)
                    report["scan_frame"] = sample.header.frame_id
                elif name == "tf":
                    report["tf_children"] = sorted({tf.child_frame_id for tf in sample.transforms})
                elif name == "clock":
                    report["clock"] = sample.clock.sec + sample.clock.nanosec * 1e-9
        if report["reached"] and all(counts.values()):
            break
        arrivals.wait(WAKE)
    report["counts"] = counts
    latencies.sort()
    if latencies:
        report["latency_ms"] = {
            "p50": latencies[len(latencies) // 2],
            "p99": latencies[min(len(latencies) - 1, int(len(latencies) * 0.99))],
            "n": len(latencies),
        }
    print(json.dumps(report), flush=True)


if __name__ == "__main__":
    main()
