"""Go-to-goal proportional controller ("turn, then drive").

Frames and units: the pose and goal are in the same planar frame (``odom``), m and rad;
the output is a body twist for ``base_link`` (x forward, yaw CCW), m/s and rad/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from otonav.control._kinematics import Pose2D
from otonav.nav._geometry import wrap_angle
from otonav.params import GoToGoalParams

__all__ = ("GoToGoalParams", "GoalCommand", "go_to_goal")


@dataclass(frozen=True, slots=True)
class GoalCommand:
    """Output of :func:`go_to_goal`: ``v`` m/s (never negative), ``omega`` rad/s (CCW
    positive), ``reached`` (within tolerance; v and omega are then 0), ``distance`` to
    the goal, m, ``heading_error``: bearing to goal minus yaw in [-pi, pi] rad (positive:
    goal to the left)."""

    v: float
    omega: float
    reached: bool
    distance: float
    heading_error: float


def go_to_goal(pose: Pose2D, goal_x: float, goal_y: float, params: GoToGoalParams) -> GoalCommand:
    """Compute a twist that drives ``pose`` towards ``(goal_x, goal_y)``.

    P-control on distance and heading error. With ``|heading_error|`` above
    ``params.turn_in_place_threshold`` the robot turns in place (v = 0); otherwise
    ``v = min(kp_lin*distance, max_v) * max(cos(heading_error), 0)``. Always
    ``omega = clamp(kp_ang*heading_error, ±max_omega)``. Never reverses (v >= 0).
    Pose and goal in odom; ValueError naming an input that is NaN or infinite.
    """
    for name, value in zip(
        ("pose.x", "pose.y", "pose.yaw", "goal_x", "goal_y"),
        (pose.x, pose.y, pose.yaw, goal_x, goal_y),
        strict=True,
    ):
        if not math.isfinite(value):
            raise ValueError(f"{name} must be finite, got {value!r}")
    dx = goal_x - pose.x
    dy = goal_y - pose.y
    distance = math.hypot(dx, dy)
    heading_error = wrap_angle(math.atan2(dy, dx) - pose.yaw)
    if distance <= params.tolerance:
        return GoalCommand(
            v=0.0, omega=0.0, reached=True, distance=distance, heading_error=heading_error
        )
    omega = min(max(params.kp_ang * heading_error, -params.max_omega), params.max_omega)
    if abs(heading_error) > params.turn_in_place_threshold:
        v = 0.0
    else:
        v = min(params.kp_lin * distance, params.max_v) * max(math.cos(heading_error), 0.0)
    return GoalCommand(
        v=v, omega=omega, reached=False, distance=distance, heading_error=heading_error
    )
