"""geometry_msgs shapes (REP 103: x forward, y left, z up; metres, radians)."""

from __future__ import annotations

import math
from typing import ClassVar

from otonav.msgs._base import Message
from otonav.msgs._std import Header

_ZERO36 = (0.0,) * 36


def quaternion_yaw(x: float, y: float, z: float, w: float) -> float:
    """The yaw (rotation about z, rad) of the unit quaternion (x, y, z, w)."""
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y**2 + z**2))


class Vector3(Message):
    """A free vector in 3-D space (geometry_msgs/Vector3)."""

    ros_type: ClassVar[str] = "geometry_msgs/msg/Vector3"
    x: float = 0.0
    y: float = 0.0
    z: float = 0.0


class Point(Message):
    """A position in 3-D space (geometry_msgs/Point)."""

    ros_type: ClassVar[str] = "geometry_msgs/msg/Point"
    x: float = 0.0
    y: float = 0.0
    z: float = 0.0


class Quaternion(Message):
    """An orientation as a unit quaternion (geometry_msgs/Quaternion)."""

    ros_type: ClassVar[str] = "geometry_msgs/msg/Quaternion"
    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    w: float = 1.0

    @classmethod
    def from_yaw(cls, yaw: float) -> Quaternion:
        return cls.fast(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))

    def yaw(self) -> float:
        return quaternion_yaw(self.x, self.y, self.z, self.w)


class Pose(Message):
    """A position and an orientation (geometry_msgs/Pose)."""

    ros_type: ClassVar[str] = "geometry_msgs/msg/Pose"
    position: Point = Point()
    orientation: Quaternion = Quaternion()


class PoseStamped(Message):
    """geometry_msgs/msg/PoseStamped: e.g. a goal on ``/goal``."""

    ros_type: ClassVar[str] = "geometry_msgs/msg/PoseStamped"
    header: Header = Header()
    pose: Pose = Pose()


class PoseWithCovariance(Message):
    """A pose with its 6x6 row-major covariance (geometry_msgs/PoseWithCovariance)."""

    ros_type: ClassVar[str] = "geometry_msgs/msg/PoseWithCovariance"
    pose: Pose = Pose()
    covariance: tuple[float, ...] = _ZERO36
    """Row-major 6x6 over (x, y, z, roll, pitch, yaw)."""


class Twist(Message):
    """geometry_msgs/msg/Twist: a velocity command on ``/cmd_vel`` (body frame)."""

    ros_type: ClassVar[str] = "geometry_msgs/msg/Twist"
    linear: Vector3 = Vector3()
    """m/s; a diff-drive robot uses x only."""
    angular: Vector3 = Vector3()
    """rad/s; a diff-drive robot uses z only."""

    @classmethod
    def planar(cls, v: float, omega: float) -> Twist:
        """A twist with forward speed ``v`` and yaw rate ``omega`` (validated)."""
        return cls(linear=Vector3(x=v), angular=Vector3(z=omega))


class TwistStamped(Message):
    """geometry_msgs/msg/TwistStamped: a velocity command with its time and frame (what
    Jazzy's diff_drive_controller takes on ``cmd_vel`` by default)."""

    ros_type: ClassVar[str] = "geometry_msgs/msg/TwistStamped"
    header: Header = Header()
    twist: Twist = Twist()


class TwistWithCovariance(Message):
    """A twist with its 6x6 row-major covariance (geometry_msgs/TwistWithCovariance)."""

    ros_type: ClassVar[str] = "geometry_msgs/msg/TwistWithCovariance"
    twist: Twist = Twist()
    covariance: tuple[float, ...] = _ZERO36


class Transform(Message):
    """A translation and a rotation between two frames (geometry_msgs/Transform)."""

    ros_type: ClassVar[str] = "geometry_msgs/msg/Transform"
    translation: Vector3 = Vector3()
    rotation: Quaternion = Quaternion()


class TransformStamped(Message):
    """A transform from ``header.frame_id`` to ``child_frame_id`` (TransformStamped)."""

    ros_type: ClassVar[str] = "geometry_msgs/msg/TransformStamped"
    header: Header = Header()
    child_frame_id: str = ""
    transform: Transform = Transform()
