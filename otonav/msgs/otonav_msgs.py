"""Messages with no ROS 2 equivalent (package ``otonav_msgs``)."""

from __future__ import annotations

from typing import ClassVar

from otonav.msgs._base import Message
from otonav.msgs.std import Header


class WheelCommand(Message):
    """Wheel angular velocity setpoints, rad/s (base controller -> bridge)."""

    ros_type: ClassVar[str] = "otonav_msgs/msg/WheelCommand"
    header: Header = Header()
    left: float = 0.0
    right: float = 0.0


class NavState(Message):
    """What the navigator is doing: ``idle`` (no goal), ``waiting`` (no fresh scan),
    ``driving``, ``blocked`` (obstacle ahead), ``reached`` or ``fault`` (the hardware
    reports a fault: it commands zero)."""

    ros_type: ClassVar[str] = "otonav_msgs/msg/NavState"
    header: Header = Header()
    state: str = "idle"
    distance_to_goal: float = 0.0
    """m, from the odometry estimate (inf with no goal)."""
    heading_error: float = 0.0
    """rad, wrapped to [-pi, pi]."""
    closest_ahead: float = 0.0
    """m, closest valid return in the guard's front sector (inf if none; -inf: a return
    closer than the lidar's range_min, REP 117)."""


class ScenarioVerdict(Message):
    """The judged outcome of a scenario (sim-time figures only, so recordings of the
    same run are byte-identical whatever the machine's speed)."""

    ros_type: ClassVar[str] = "otonav_msgs/msg/ScenarioVerdict"
    header: Header = Header()
    scenario: str = ""
    passed: bool = False
    reached: bool = False
    reason: str = ""
    time_to_goal: float = -1.0
    """s of sim time; -1 when the goal was not reached."""
    min_clearance: float = 0.0
    final_distance: float = 0.0
    path_length: float = 0.0
    sim_time: float = 0.0
