"""Message types, shaped like the ROS 2 messages they stand for (frozen pydantic)."""

from otonav.msgs._base import Message
from otonav.msgs.geometry import (
    Point,
    Pose,
    PoseStamped,
    PoseWithCovariance,
    Quaternion,
    Transform,
    TransformStamped,
    Twist,
    TwistStamped,
    TwistWithCovariance,
    Vector3,
)
from otonav.msgs.hardware import (
    DiagnosticArray,
    DiagnosticStatus,
    Frame,
    HardwareStatus,
    KeyValue,
)
from otonav.msgs.otonav_msgs import (
    NavDiagnostics,
    NavState,
    SafetyState,
    ScenarioVerdict,
    WheelCommand,
)
from otonav.msgs.sensors import (
    Imu,
    LaserScan,
    MapMetaData,
    OccupancyGrid,
    Odometry,
    TFMessage,
)
from otonav.msgs.std import Clock, Header, Log, Time

__all__ = (
    "Clock",
    "DiagnosticArray",
    "DiagnosticStatus",
    "Frame",
    "HardwareStatus",
    "Header",
    "Imu",
    "KeyValue",
    "LaserScan",
    "Log",
    "MapMetaData",
    "Message",
    "NavDiagnostics",
    "NavState",
    "OccupancyGrid",
    "Odometry",
    "Point",
    "Pose",
    "PoseStamped",
    "PoseWithCovariance",
    "Quaternion",
    "SafetyState",
    "ScenarioVerdict",
    "TFMessage",
    "Time",
    "Transform",
    "TransformStamped",
    "Twist",
    "TwistStamped",
    "TwistWithCovariance",
    "Vector3",
    "WheelCommand",
)
