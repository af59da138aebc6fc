"""sensor_msgs, nav_msgs and tf2_msgs shapes."""

from __future__ import annotations

from typing import ClassVar

from otonav.msgs._base import Message
from otonav.msgs._geometry import (
    Pose,
    PoseWithCovariance,
    Quaternion,
    TransformStamped,
    TwistWithCovariance,
    Vector3,
)
from otonav.msgs._std import Header, Time

_ZERO9 = (0.0,) * 9


class Odometry(Message):
    """nav_msgs/msg/Odometry: pose in ``header.frame_id`` (odom), twist in
    ``child_frame_id`` (base_link)."""

    ros_type: ClassVar[str] = "nav_msgs/msg/Odometry"
    header: Header = Header()
    child_frame_id: str = ""
    pose: PoseWithCovariance = PoseWithCovariance()
    twist: TwistWithCovariance = TwistWithCovariance()


class Imu(Message):
    """sensor_msgs/msg/Imu: orientation, angular velocity (rad/s), linear acceleration
    (m/s², gravity included)."""

    ros_type: ClassVar[str] = "sensor_msgs/msg/Imu"
    header: Header = Header()
    orientation: Quaternion = Quaternion()
    orientation_covariance: tuple[float, ...] = _ZERO9
    angular_velocity: Vector3 = Vector3()
    angular_velocity_covariance: tuple[float, ...] = _ZERO9
    linear_acceleration: Vector3 = Vector3()
    linear_acceleration_covariance: tuple[float, ...] = _ZERO9


class JointState(Message):
    """sensor_msgs/msg/JointState: each joint's position (rad), velocity (rad/s) and
    effort (N m), by name (empty: not measured)."""

    ros_type: ClassVar[str] = "sensor_msgs/msg/JointState"
    header: Header = Header()
    name: tuple[str, ...] = ()
    position: tuple[float, ...] = ()
    velocity: tuple[float, ...] = ()
    effort: tuple[float, ...] = ()


class LaserScan(Message):
    """sensor_msgs/msg/LaserScan: beam i at ``angle_min + i * angle_increment``
    (counter-clockwise from the laser's +x); +inf where nothing was hit (REP 117)."""

    ros_type: ClassVar[str] = "sensor_msgs/msg/LaserScan"
    header: Header = Header()
    angle_min: float = 0.0
    angle_max: float = 0.0
    angle_increment: float = 0.0
    time_increment: float = 0.0
    scan_time: float = 0.0
    range_min: float = 0.0
    range_max: float = 0.0
    ranges: tuple[float, ...] = ()
    intensities: tuple[float, ...] = ()


class TFMessage(Message):
    """tf2_msgs/msg/TFMessage: transforms on ``/tf`` and ``/tf_static``."""

    ros_type: ClassVar[str] = "tf2_msgs/msg/TFMessage"
    transforms: tuple[TransformStamped, ...] = ()


class MapMetaData(Message):
    """nav_msgs/msg/MapMetaData: a grid's resolution, size and where its cell (0, 0)
    sits (``origin``: the corner of that cell, in the map's frame)."""

    ros_type: ClassVar[str] = "nav_msgs/msg/MapMetaData"
    map_load_time: Time = Time()
    resolution: float = 0.0
    """m per cell."""
    width: int = 0
    """cells along x."""
    height: int = 0
    """cells along y."""
    origin: Pose = Pose()


class OccupancyGrid(Message):
    """nav_msgs/msg/OccupancyGrid: row-major cells from ``info.origin``, -1 unknown,
    else the probability of occupied in percent (0-100); e.g. ``/map``."""

    ros_type: ClassVar[str] = "nav_msgs/msg/OccupancyGrid"
    header: Header = Header()
    info: MapMetaData = MapMetaData()
    data: tuple[int, ...] = ()
