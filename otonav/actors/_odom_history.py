"""Recent odometry by stamp: where the robot was when a scan was taken."""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable

from otonav.msgs import Odometry
from otonav.msgs._flat import reader
from otonav.msgs._geometry import quaternion_yaw

Pose = tuple[float, float, float]


# Read through otonav.msgs._flat.reader: the bridge's odometry is a flat message, whose
# nested objects are never built this way (4.4 us each; the numbers are the same).
_read_stamp = reader(Odometry, "header.stamp.sec", "header.stamp.nanosec")
_read_pose = reader(
    Odometry,
    "pose.pose.position.x",
    "pose.pose.position.y",
    "pose.pose.orientation.x",
    "pose.pose.orientation.y",
    "pose.pose.orientation.z",
    "pose.pose.orientation.w",
)
_read_twist = reader(Odometry, "twist.twist.linear.x", "twist.twist.angular.z")


def _stamp(odom: Odometry) -> float:
    sec, nanosec = _read_stamp(odom)
    return float(sec + nanosec * 1e-9)


def _pose(odom: Odometry) -> Pose:
    x, y, qx, qy, qz, qw = _read_pose(odom)
    return (x, y, quaternion_yaw(qx, qy, qz, qw))


class OdomHistory:
    """The last ``size`` odometry messages; decoded only when asked (odometry comes at
    100 Hz, a pose is wanted at 10-20 Hz)."""

    def __init__(self, size: int = 32) -> None:
        self._items: deque[Odometry] = deque(maxlen=size)

    def extend(self, odoms: Iterable[Odometry]) -> None:
        """Add messages, oldest first (``Subscription.drain``)."""
        self._items.extend(odoms)

    @property
    def latest(self) -> tuple[float, Pose, float, float] | None:
        """(stamp s, pose (x, y, yaw), v m/s, omega rad/s) of the newest message."""
        if not self._items:
            return None
        odom = self._items[-1]
        v, omega = _read_twist(odom)
        return _stamp(odom), _pose(odom), v, omega

    @property
    def latest_stamp(self) -> float | None:
        """The newest message's stamp, s (None with no odometry yet): its freshness,
        without decoding its pose and twist."""
        if not self._items:
            return None
        return _stamp(self._items[-1])

    def pose_at(self, stamp: float) -> Pose | None:
        """The pose with the stamp nearest ``stamp`` (None with no odometry yet)."""
        if not self._items:
            return None
        # Newest first: stamps only grow, so the gap shrinks until the nearest one.
        best, gap = self._items[-1], abs(_stamp(self._items[-1]) - stamp)
        for odom in reversed(self._items):
            this = abs(_stamp(odom) - stamp)
            if this > gap:
                break
            best, gap = odom, this
        return _pose(best)
