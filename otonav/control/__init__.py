"""Pure diff-drive math: kinematics, odometry, command limits (no I/O)."""

from otonav.control.kinematics import (
    DiffDriveGeometry,
    Pose2D,
    integrate_odometry,
    limit_twist,
    twist_to_wheels,
    wheels_to_twist,
)

__all__ = (
    "DiffDriveGeometry",
    "Pose2D",
    "integrate_odometry",
    "limit_twist",
    "twist_to_wheels",
    "wheels_to_twist",
)
