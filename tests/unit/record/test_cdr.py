"""CDR encoding and ros2msg schemas, checked against mcap_ros2 (an independent oracle).

Every message is encoded by ``otonav.record.cdr.encode`` and then (a) decoded by
mcap_ros2's generic decoder from our schema text and compared field by field with the
original, and (b) compared byte for byte with mcap_ros2's own generic serializer. The
schema texts themselves are pinned against the ROS 2 ``.msg`` definitions written out
below, and a few payloads against bytes worked out by hand.
"""

from __future__ import annotations

import math
import struct
from typing import Any, ClassVar

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from mcap.records import Schema
from mcap_ros2._dynamic import serialize_dynamic
from mcap_ros2.decoder import DecoderFactory

from otonav import msgs
from otonav.msgs import (
    Clock,
    DiagnosticArray,
    DiagnosticStatus,
    Frame,
    HardwareStatus,
    Header,
    Imu,
    LaserScan,
    Log,
    MapMetaData,
    Message,
    NavState,
    OccupancyGrid,
    Odometry,
    Parameter,
    ParameterEvent,
    ParameterValue,
    Point,
    Pose,
    PoseStamped,
    PoseWithCovariance,
    Quaternion,
    TFMessage,
    Time,
    Transform,
    TransformStamped,
    Twist,
    TwistWithCovariance,
    Vector3,
    WheelCommand,
)
from otonav.msgs import KeyValue as DiagKeyValue
from otonav.record._schemas import schema_for
from otonav.record.cdr import decode as decode_cdr
from otonav.record.cdr import encode

pytestmark = pytest.mark.unit

INF = math.inf


# --- test-only message types (generated layouts) -----------------------------------


class Empty(Message):
    ros_type: ClassVar[str] = "otonav_test_msgs/msg/Empty"


class Everything(Message):
    """Every kind of field a generated layout supports, in an order that exercises
    alignment after strings and (empty) sequences."""

    ros_type: ClassVar[str] = "otonav_test_msgs/msg/Everything"
    flag: bool = False
    label: str = ""
    count: int = 0
    ratio: float = 0.0
    stamp: Time = Time()
    values: tuple[float, ...] = ()
    after_values: float = 0.0
    counts: tuple[int, ...] = ()
    flags: tuple[bool, ...] = ()
    labels: tuple[str, ...] = ()
    poses: tuple[Pose, ...] = ()
    nothing: Empty = Empty()
    tail: float = 0.0


# --- the oracle ---------------------------------------------------------------------


def mcap_schema(kind: type[Message]) -> Schema:
    name, text = schema_for(kind)
    return Schema(id=1, name=name, encoding="ros2msg", data=text.encode())


def decode(message: Message) -> Any:
    decoder = DecoderFactory().decoder_for("cdr", mcap_schema(type(message)))
    assert decoder is not None
    return decoder(encode(message))


def plain(value: Any) -> Any:
    """Our message as the dicts and lists mcap_ros2's serializer takes."""
    if isinstance(value, Message):
        return {name: plain(getattr(value, name)) for name in type(value).model_fields}
    if isinstance(value, tuple):
        return [plain(item) for item in value]
    return value


def reference_bytes(message: Message) -> bytes:
    name, text = schema_for(type(message))
    serializer = serialize_dynamic(name, text)[name]
    return bytes(serializer(plain(message)))


FLOAT32_FIELDS: dict[type[Message], frozenset[str]] = {
    MapMetaData: frozenset({"resolution"}),
    LaserScan: frozenset(
        {
            "angle_min",
            "angle_max",
            "angle_increment",
            "time_increment",
            "scan_time",
            "range_min",
            "range_max",
            "ranges",
            "intensities",
        }
    ),
}
"""Fields ROS 2 holds as float32 (sensor_msgs/LaserScan, nav_msgs/MapMetaData); all other
floats are float64."""


def assert_same(decoded: Any, original: Message, where: str = "") -> None:
    """Each field of ``decoded`` (mcap_ros2's) equals ``original``'s: float32 fields
    after rounding to float32, NaN equal to NaN."""
    kind = type(original)
    for name in kind.model_fields:
        path = f"{where}{kind.__name__}.{name}"
        want, got = getattr(original, name), getattr(decoded, name)
        if isinstance(got, bytes):  # mcap_ros2 gives uint8[N] as bytes
            got = tuple(got)
        if isinstance(want, Message):
            assert_same(got, want, path + ".")
        elif isinstance(want, tuple) and want and isinstance(want[0], Message):
            assert len(got) == len(want), path
            for g, w in zip(got, want, strict=True):
                assert_same(g, w, path + "[].")
        elif isinstance(want, tuple) and want and isinstance(want[0], str):
            assert list(got) == list(want), path
        elif isinstance(want, float | tuple) and not isinstance(want, bool):
            dtype = np.float32 if name in FLOAT32_FIELDS.get(kind, ()) else None
            if isinstance(want, tuple) and want and isinstance(want[0], int | bool):
                dtype = None
            expected = np.asarray(want, dtype=dtype)
            np.testing.assert_array_equal(np.asarray(got, dtype=dtype), expected, err_msg=path)
            assert np.shape(got) == np.shape(want), path
        else:
            assert got == want, path
            assert type(got) is type(want), path


def check(message: Message) -> None:
    """Decoded fields equal the original, and the bytes equal mcap_ros2's own; our own
    decoder (replay's) gives the same fields back, as the same types, and bytes that
    encode identically."""
    assert_same(decode(message), message)
    data = encode(message)
    assert data == reference_bytes(message)
    ours = decode_cdr(type(message), data)
    assert type(ours) is type(message)
    assert_same(ours, message)
    assert encode(ours) == data


# --- samples ------------------------------------------------------------------------

STAMPS = (
    Time(sec=0, nanosec=0),
    Time(sec=1_700_000_000, nanosec=999_999_999),
    Time(sec=-2, nanosec=300_000_000),
)
# Frame ids of every length mod 4 (and multi-byte UTF-8), so what follows them starts
# at every alignment.
FRAMES = ("", "a", "ab", "odom", "base_link", "laser_frame", "ŝkanilo", "激光雷达")
HEADERS = tuple(
    Header(stamp=STAMPS[i % len(STAMPS)], frame_id=frame) for i, frame in enumerate(FRAMES)
)
COV36 = tuple(float(i) * -0.5 + 0.125 for i in range(36))
COV9 = (1e-3, 0.0, -0.0, 0.0, 2.5e-3, 0.0, -1e300, 0.0, INF)
POSES = (
    Pose(),
    Pose(position=Point(x=1.5, y=-2.25, z=0.0), orientation=Quaternion.from_yaw(-2.0)),
)
TRANSFORMS = tuple(
    TransformStamped(
        header=HEADERS[i],
        child_frame_id=child,
        transform=Transform(
            translation=Vector3(x=-0.1 * i, y=0.2, z=1e-9), rotation=Quaternion.from_yaw(i)
        ),
    )
    for i, child in enumerate(("base_link", "laser", "x"))
)
RANGES = (*tuple(0.1 + 0.037 * i for i in range(357)), INF, INF, 1e-45)


def samples() -> dict[type[Message], list[Message]]:
    """Non-trivial instances of every message type we record."""
    return {
        Time: list(STAMPS),
        Header: list(HEADERS),
        Clock: [Clock(clock=s) for s in STAMPS],
        Frame: [
            Frame(header=HEADERS[1], id=0x02D, dlc=8, data=(0, 0, 0x20, 0xC0, 0, 0, 0x80, 0x3E)),
            Frame(header=HEADERS[6], id=0x40, is_error=True, dlc=0, data=(0,) * 8),
            Frame(id=0x7FF, is_rtr=True, is_extended=False, dlc=1, data=(255,) + (0,) * 7),
        ],
        DiagnosticStatus: [
            DiagnosticStatus(
                level=DiagnosticStatus.ERROR,
                name="bridge: hardware",
                message="node 9 (left wheel): no heartbeat",
                hardware_id="CanBusInterface",
                values=(DiagKeyValue(key="ready", value="false"), DiagKeyValue(key="ŝ")),
            ),
            DiagnosticStatus(),
        ],
        DiagnosticArray: [
            DiagnosticArray(
                header=HEADERS[2],
                status=(DiagnosticStatus(level=1, name="a"), DiagnosticStatus(message="b")),
            ),
            DiagnosticArray(),
        ],
        HardwareStatus: [
            HardwareStatus(header=HEADERS[3], level=2, ready=False, fault="bus_off", message="x"),
            HardwareStatus(),
        ],
        Log: [
            Log(stamp=STAMPS[1], level=Log.WARN, name="nav", msg="blocked", line=42),
            Log(
                stamp=STAMPS[2],
                level=Log.FATAL,
                name="actor.bridge",
                msg="crashed: ZeroDivisionError — ünïcode",
                file="otonav/actors/_bridge.py",
                function="run",
                line=4_000_000_000,
            ),
            Log(),
        ],
        Vector3: [Vector3(x=-1.0, y=1e-300, z=INF)],
        Point: [Point(x=3.0, y=-4.0, z=0.5)],
        Quaternion: [Quaternion.from_yaw(1.0), Quaternion(x=-0.5, y=0.5, z=-0.5, w=0.5)],
        Pose: list(POSES),
        PoseStamped: [PoseStamped(header=h, pose=POSES[i % 2]) for i, h in enumerate(HEADERS)],
        PoseWithCovariance: [PoseWithCovariance(pose=POSES[1], covariance=COV36)],
        Twist: [Twist.planar(0.5, -1.25), Twist()],
        TwistWithCovariance: [TwistWithCovariance(twist=Twist.planar(-0.3, 0.1), covariance=COV36)],
        Transform: [t.transform for t in TRANSFORMS],
        TransformStamped: list(TRANSFORMS),
        Odometry: [
            Odometry(
                header=h,
                child_frame_id=FRAMES[-1 - i],
                pose=PoseWithCovariance(pose=POSES[1], covariance=COV36),
                twist=TwistWithCovariance(twist=Twist.planar(0.7, -0.2), covariance=COV36[::-1]),
            )
            for i, h in enumerate(HEADERS)
        ],
        Imu: [
            Imu(
                header=h,
                orientation=Quaternion.from_yaw(0.3),
                orientation_covariance=COV9,
                angular_velocity=Vector3(z=-0.5),
                angular_velocity_covariance=COV9[::-1],
                linear_acceleration=Vector3(x=0.1, z=9.81),
                linear_acceleration_covariance=(-1.0,) * 9,
            )
            for h in HEADERS[:4]
        ],
        LaserScan: [
            *(
                LaserScan(
                    header=h,
                    angle_min=-math.pi,
                    angle_max=math.pi,
                    angle_increment=2 * math.pi / 360,
                    time_increment=1e-5,
                    scan_time=0.1,
                    range_min=0.12,
                    range_max=12.0,
                    ranges=RANGES[: 360 - i],
                    intensities=tuple(float(j % 7) for j in range(i)),
                )
                for i, h in enumerate(HEADERS)
            ),
            LaserScan(),
        ],
        TFMessage: [
            TFMessage(),
            TFMessage(transforms=TRANSFORMS[:1]),
            TFMessage(transforms=TRANSFORMS),
        ],
        WheelCommand: [WheelCommand(header=h, left=-3.5, right=7.25) for h in HEADERS[:4]],
        NavState: [
            NavState(
                header=h,
                state=state,
                distance_to_goal=INF,
                heading_error=-math.pi,
                closest_ahead=0.35,
            )
            for h, state in zip(HEADERS, ("idle", "driving", "blocked", "reached"), strict=False)
        ],
        MapMetaData: [
            MapMetaData(),
            MapMetaData(
                map_load_time=STAMPS[2], resolution=0.05, width=3, height=2, origin=POSES[1]
            ),
        ],
        OccupancyGrid: [
            OccupancyGrid(),
            OccupancyGrid(
                header=HEADERS[1],
                info=MapMetaData(
                    map_load_time=STAMPS[1], resolution=0.1, width=3, height=2, origin=POSES[0]
                ),
                data=(-1, 0, 100, 50, -1, 7),
            ),
        ],
        Empty: [Empty()],
        Everything: [
            Everything(),
            Everything(
                flag=True,
                label="abc",
                count=-(2**62),
                ratio=-0.1,
                stamp=STAMPS[2],
                values=(1.0, -2.5, INF),
                after_values=3.0,
                counts=(-1, 0, 2**63 - 1),
                flags=(True, False, True),
                labels=("", "a", "ŝkanilo"),
                poses=POSES,
                tail=-4.0,
            ),
            Everything(label="abcde", values=(), after_values=1.0, labels=("xyz",), tail=2.0),
        ],
        ParameterValue: [*PARAMETER_VALUES],
        Parameter: [Parameter(), Parameter(name="params.dwa.max_v", value=PARAMETER_VALUES[1])],
        ParameterEvent: [
            ParameterEvent(),
            ParameterEvent(
                stamp=STAMPS[2],
                node="/nav",
                new_parameters=(Parameter(name="a", value=PARAMETER_VALUES[2]),),
                changed_parameters=tuple(
                    Parameter(name=f"p{i}", value=v) for i, v in enumerate(PARAMETER_VALUES)
                ),
            ),
        ],
    }


PARAMETER_VALUES = [
    ParameterValue(),
    ParameterValue(type=ParameterValue.DOUBLE, double_value=0.15),
    ParameterValue(
        type=9,
        bool_value=True,
        integer_value=-(2**62),
        string_value="ŝkanilo",
        byte_array_value=(0, 7, 255),
        bool_array_value=(True, False),
        integer_array_value=(-1, 2**63 - 1),
        double_array_value=(0.5, -INF),
        string_array_value=("", "abc"),
    ),
]


SAMPLES = samples()


def every_message_type() -> list[type[Message]]:
    return [
        kind
        for kind in vars(msgs).values()
        if isinstance(kind, type) and issubclass(kind, Message) and kind is not Message
    ]


def example(kind: type[Message], i: int = 1) -> Message:
    """A sample of ``kind``; for a type this file does not know (e.g. one added to
    otonav.msgs later), one built from its fields."""
    if kind in SAMPLES:
        return SAMPLES[kind][i % len(SAMPLES[kind])]
    values: dict[str, Any] = {}
    for name, info in kind.model_fields.items():
        tp = info.annotation
        if tp is bool:
            values[name] = i % 2 == 0
        elif tp is int:
            values[name] = -123_456_789_012 * (i + 1)
        elif tp is float:
            values[name] = -1.25 * (i + 1)
        elif tp is str:
            values[name] = FRAMES[(i + len(name)) % len(FRAMES)]
        elif isinstance(tp, type) and issubclass(tp, Message):
            values[name] = example(tp, i + len(name))
        elif tp == tuple[float, ...]:
            values[name] = (1.0, -INF, 0.5)[: i % 4]
        elif tp == tuple[str, ...]:
            values[name] = FRAMES[: i % 4]
        else:
            pytest.fail(f"no example for {kind.__name__}.{name}: {tp!r}")
    return kind(**values)


# --- round trips through the independent decoder -----------------------------------


@pytest.mark.parametrize("kind", every_message_type(), ids=lambda k: k.__name__)
def test_every_message_type_round_trips(kind: type[Message]) -> None:
    for i in range(max(3, len(SAMPLES.get(kind, ())))):
        check(example(kind, i))


@pytest.mark.parametrize("kind", list(SAMPLES), ids=lambda k: k.__name__)
def test_samples_round_trip_and_match_mcap_ros2_bytes(kind: type[Message]) -> None:
    for message in SAMPLES[kind]:
        check(message)


def test_laser_scan_keeps_inf_and_rounds_to_float32() -> None:
    scan = SAMPLES[LaserScan][0]
    assert isinstance(scan, LaserScan)
    decoded = decode(scan)
    assert decoded.ranges[-3:-1] == [INF, INF]
    assert decoded.angle_min == float(np.float32(-math.pi)) != -math.pi
    assert len(decoded.ranges) == 360
    assert decoded.intensities == []


def test_log_constants_are_in_the_schema() -> None:
    from mcap_ros2._vendor.rosidl_adapter.parser import parse_message_string

    _, text = schema_for(Log)
    top = text.split("=" * 80)[0]
    spec = parse_message_string("rcl_interfaces", "Log", top)
    constants = {c.name: (c.type, c.value) for c in spec.constants}
    assert constants == {
        "DEBUG": ("byte", 10),
        "INFO": ("byte", 20),
        "WARN": ("byte", 30),
        "ERROR": ("byte", 40),
        "FATAL": ("byte", 50),
    }


# --- bytes worked out by hand ---------------------------------------------------------


def test_clock_bytes_by_hand() -> None:
    clock = Clock(clock=Time(sec=-2, nanosec=300_000_000))
    assert encode(clock) == b"\x00\x01\x00\x00" + struct.pack("<iI", -2, 300_000_000)


def test_wheel_command_alignment_by_hand() -> None:
    # Payload: sec, nanosec (8) | len 3 (4) | "ab\0" (3) -> offset 15, pad 1 to 16 | 2 doubles.
    command = WheelCommand(header=Header(stamp=Time(sec=1, nanosec=2), frame_id="ab"), left=-3.5)
    expected = (
        b"\x00\x01\x00\x00"
        + struct.pack("<iII", 1, 2, 3)
        + b"ab\x00"
        + b"\x00"
        + struct.pack("<dd", -3.5, 0.0)
    )
    assert encode(command) == expected


def test_empty_string_and_empty_sequence_by_hand() -> None:
    # Payload: sec, nanosec | len 1, "\0" -> 13, pad 3 | 7 float32 (28) -> 44 |
    # count 0 | count 0. An empty sequence has no element to align.
    scan = LaserScan(range_max=1.0)
    expected = (
        b"\x00\x01\x00\x00"
        + struct.pack("<iII", 0, 0, 1)
        + b"\x00\x00\x00\x00"
        + struct.pack("<7f", 0, 0, 0, 0, 0, 0, 1.0)
        + struct.pack("<II", 0, 0)
    )
    assert encode(scan) == expected


def test_8_byte_sequences_and_empty_messages_by_hand() -> None:
    # Payload offsets: flag @0 | pad 3, label len 1 @4, "\0" @8 | pad 7, count @16 |
    # ratio @24 | stamp @32 | values: count 1 @40, pad 4 (element alignment), 1.5 @48 |
    # after_values @56 | counts: count 0 @64 -- empty, so no padding -- | flags: count 0
    # @68 | labels: count 0 @72 | poses: count 0 @76 | nothing (no fields): uint8 0 @80 |
    # pad 7, tail @88.
    message = Everything(flag=True, count=-7, values=(1.5,), tail=2.0)
    expected = (
        b"\x00\x01\x00\x00"
        + b"\x01" + bytes(3)
        + struct.pack("<I", 1) + b"\x00" + bytes(7)
        + struct.pack("<qdiI", -7, 0.0, 0, 0)
        + struct.pack("<I", 1) + bytes(4) + struct.pack("<dd", 1.5, 0.0)
        + struct.pack("<4I", 0, 0, 0, 0)
        + b"\x00" + bytes(7)
        + struct.pack("<d", 2.0)
    )  # fmt: skip
    assert encode(message) == expected


# --- what the encoder refuses -------------------------------------------------------


@pytest.mark.parametrize(
    "message",
    [
        PoseWithCovariance.model_construct(pose=Pose(), covariance=(0.0,) * 35),
        Imu.model_construct(
            header=Header(),
            orientation=Quaternion(),
            orientation_covariance=(0.0,) * 9,
            angular_velocity=Vector3(),
            angular_velocity_covariance=(0.0,) * 10,
            linear_acceleration=Vector3(),
            linear_acceleration_covariance=(0.0,) * 8,
        ),
        Log(level=256),
        Clock(clock=Time.model_construct(sec=0, nanosec=-1)),
        Clock(clock=Time.model_construct(sec=2**31, nanosec=0)),
        LaserScan(ranges=(1e39,)),
    ],
    ids=["cov35", "imu-cov", "level256", "nanosec<0", "sec>int32", "float32-overflow"],
)
def test_values_the_ros_type_cannot_hold_are_refused(message: Message) -> None:
    with pytest.raises(ValueError, match=r"cannot encode|fixed array"):
        encode(message)


# --- schema texts, pinned against the ROS 2 .msg definitions ------------------------

ROS_DEFINITIONS: dict[type[Message], str] = {
    Time: "int32 sec\nuint32 nanosec",
    Header: "builtin_interfaces/Time stamp\nstring frame_id",
    Clock: "builtin_interfaces/Time clock",
    Log: (
        "byte DEBUG=10\nbyte INFO=20\nbyte WARN=30\nbyte ERROR=40\nbyte FATAL=50\n"
        "builtin_interfaces/Time stamp\nuint8 level\nstring name\nstring msg\n"
        "string file\nstring function\nuint32 line"
    ),
    Vector3: "float64 x\nfloat64 y\nfloat64 z",
    Point: "float64 x\nfloat64 y\nfloat64 z",
    Quaternion: "float64 x\nfloat64 y\nfloat64 z\nfloat64 w",
    Pose: "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation",
    PoseStamped: "std_msgs/Header header\ngeometry_msgs/Pose pose",
    PoseWithCovariance: "geometry_msgs/Pose pose\nfloat64[36] covariance",
    Twist: "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular",
    TwistWithCovariance: "geometry_msgs/Twist twist\nfloat64[36] covariance",
    Transform: "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation",
    TransformStamped: (
        "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform"
    ),
    Odometry: (
        "std_msgs/Header header\nstring child_frame_id\n"
        "geometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist"
    ),
    Imu: (
        "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n"
        "float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n"
        "float64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\n"
        "float64[9] linear_acceleration_covariance"
    ),
    LaserScan: (
        "std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\n"
        "float32 angle_increment\nfloat32 time_increment\nfloat32 scan_time\n"
        "float32 range_min\nfloat32 range_max\nfloat32[] ranges\nfloat32[] intensities"
    ),
    TFMessage: "geometry_msgs/TransformStamped[] transforms",
    WheelCommand: "std_msgs/Header header\nfloat64 left\nfloat64 right",
    NavState: (
        "std_msgs/Header header\nstring state\nfloat64 distance_to_goal\n"
        "float64 heading_error\nfloat64 closest_ahead"
    ),
    Everything: (
        "bool flag\nstring label\nint64 count\nfloat64 ratio\nbuiltin_interfaces/Time stamp\n"
        "float64[] values\nfloat64 after_values\nint64[] counts\nbool[] flags\n"
        "string[] labels\ngeometry_msgs/Pose[] poses\notonav_test_msgs/Empty nothing\n"
        "float64 tail"
    ),
    Empty: "",
}


def split_definition(text: str) -> tuple[str, dict[str, str]]:
    """rosbag2's concatenation -> (top-level text, {dependency: text})."""
    top, *parts = text.split("\n" + "=" * 80 + "\n")
    deps: dict[str, str] = {}
    for part in parts:
        header, _, body = part.partition("\n")
        assert header.startswith("MSG: "), header
        name = header.removeprefix("MSG: ")
        assert name not in deps, f"{name} twice"
        deps[name] = body
    return top, deps


def short(kind: type[Message]) -> str:
    pkg, _, name = kind.ros_type.split("/")
    return f"{pkg}/{name}"


@pytest.mark.parametrize("kind", list(ROS_DEFINITIONS), ids=lambda k: k.__name__)
def test_schema_matches_the_ros_definition(kind: type[Message]) -> None:
    name, text = schema_for(kind)
    assert name == kind.ros_type
    top, deps = split_definition(text)
    assert top.strip() == ROS_DEFINITIONS[kind]
    by_short_name = {short(k): k for k in ROS_DEFINITIONS}
    for dep, body in deps.items():
        assert body.strip() == ROS_DEFINITIONS[by_short_name[dep]], dep


def test_schema_lists_every_dependency_once() -> None:
    _, text = schema_for(Odometry)
    _, deps = split_definition(text)
    assert sorted(deps) == sorted(
        [
            "std_msgs/Header",
            "builtin_interfaces/Time",
            "geometry_msgs/PoseWithCovariance",
            "geometry_msgs/Pose",
            "geometry_msgs/Point",
            "geometry_msgs/Quaternion",
            "geometry_msgs/TwistWithCovariance",
            "geometry_msgs/Twist",
            "geometry_msgs/Vector3",
        ]
    )
    assert schema_for(Odometry) is schema_for(Odometry)  # cached


def test_a_field_with_no_ros_type_is_refused() -> None:
    class Bad(Message):
        ros_type: ClassVar[str] = "otonav_test_msgs/msg/Bad"
        table: complex = 0j

    with pytest.raises(TypeError, match="no ROS 2 type"):
        schema_for(Bad)


# --- properties ---------------------------------------------------------------------

texts = st.text(st.characters(codec="utf-8", exclude_characters="\x00"), max_size=12)
stamps = st.builds(Time, sec=st.integers(-(2**31), 2**31 - 1), nanosec=st.integers(0, 999_999_999))
headers = st.builds(Header, stamp=stamps, frame_id=texts)
f32 = st.floats(width=32)
f64 = st.floats()


@settings(max_examples=150, deadline=None)
@given(
    header=headers,
    scalars=st.lists(f32, min_size=7, max_size=7),
    ranges=st.lists(f32, max_size=400),
    intensities=st.lists(f32, max_size=50),
)
def test_property_laser_scan(
    header: Header, scalars: list[float], ranges: list[float], intensities: list[float]
) -> None:
    names = (
        "angle_min",
        "angle_max",
        "angle_increment",
        "time_increment",
        "scan_time",
        "range_min",
        "range_max",
    )
    scan = LaserScan(
        header=header,
        **dict(zip(names, scalars, strict=True)),
        ranges=tuple(ranges),
        intensities=tuple(intensities),
    )
    check(scan)


vectors = st.builds(Vector3, x=f64, y=f64, z=f64)


@settings(max_examples=150, deadline=None)
@given(
    header=headers,
    child=texts,
    position=st.builds(Point, x=f64, y=f64, z=f64),
    orientation=st.builds(Quaternion, x=f64, y=f64, z=f64, w=f64),
    linear=vectors,
    angular=vectors,
    covariances=st.lists(st.lists(f64, min_size=36, max_size=36), min_size=2, max_size=2),
)
def test_property_odometry(
    header: Header,
    child: str,
    position: Point,
    orientation: Quaternion,
    linear: Vector3,
    angular: Vector3,
    covariances: list[list[float]],
) -> None:
    odometry = Odometry(
        header=header,
        child_frame_id=child,
        pose=PoseWithCovariance(
            pose=Pose(position=position, orientation=orientation),
            covariance=tuple(covariances[0]),
        ),
        twist=TwistWithCovariance(
            twist=Twist(linear=linear, angular=angular), covariance=tuple(covariances[1])
        ),
    )
    check(odometry)


# --- our decoder (replay) on what is not CDR of the type ----------------------------


def test_decoder_refuses_big_endian_and_short_data() -> None:
    data = encode(Odometry())
    with pytest.raises(ValueError, match="little-endian"):
        decode_cdr(Odometry, b"\x00\x00\x00\x00" + data[4:])
    with pytest.raises(ValueError, match="cannot decode nav_msgs/msg/Odometry"):
        decode_cdr(Odometry, data[: len(data) // 2])
    with pytest.raises(ValueError, match="cannot decode"):
        decode_cdr(NavState, encode(NavState(state="driving"))[:10] + b"\xff" * 4)


# --- the generated encoders: an element starts anywhere -----------------------------


def test_array_elements_at_every_offset_match_mcap_ros2_bytes() -> None:
    # A top-level encoder resolves its padding when it is compiled; an element of an
    # array starts wherever the previous element ended, so its padding must follow the
    # buffer. Elements with strings of every length mod 8 before them (and inside).
    transforms = tuple(
        TransformStamped(
            header=HEADERS[i % len(HEADERS)],
            child_frame_id="x" * i,
            transform=Transform(
                translation=Vector3(x=i + 0.5, y=-1.0, z=2.0),
                rotation=Quaternion(x=0.0, y=0.0, z=math.sin(i), w=math.cos(i)),
            ),
        )
        for i in range(9)
    )
    statuses = tuple(
        DiagnosticStatus(
            level=i % 4,
            name="n" * i,
            message="m" * (7 - i % 8),
            hardware_id="",
            values=tuple(DiagKeyValue(key="k" * j, value="v" * (i + j)) for j in range(i % 3)),
        )
        for i in range(9)
    )
    for message in (
        TFMessage(transforms=transforms),
        DiagnosticArray(header=HEADERS[5], status=statuses),
    ):
        check(message)
