"""Pure diff-drive math: kinematics, odometry, command limits (no I/O)."""

from otonav.control._kinematics import (
    DiffDriveGeometry,
    Pose2D,
    integrate_odometry,
    limit_twist,
    twist_to_wheels,
    wheels_to_twist,
)
from otonav.control._odometry import OdometryEstimate, estimate_odometry

__all__ = (
    "DiffDriveGeometry",
    "OdometryEstimate",
    "Pose2D",
    "estimate_odometry",
    "integrate_odometry",
    "limit_twist",
    "twist_to_wheels",
    "wheels_to_twist",
)
