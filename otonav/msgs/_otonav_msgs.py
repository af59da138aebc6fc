"""Messages with no ROS 2 equivalent (package ``otonav_msgs``)."""

from __future__ import annotations

from typing import ClassVar

from otonav.msgs._base import Message
from otonav.msgs._std import Header


class WheelCommand(Message):
    """Wheel angular velocity setpoints, rad/s (base controller -> bridge)."""

    ros_type: ClassVar[str] = "otonav_msgs/msg/WheelCommand"
    header: Header = Header()
    left: float = 0.0
    right: float = 0.0


class NavState(Message):
    """What the navigator is doing: ``idle`` (no goal), ``waiting`` (no fresh scan),
    ``driving``, ``avoiding`` (steering around a return), ``blocked`` (obstacle ahead,
    no way to move on), ``recovering`` (a recovery behaviour), ``unreachable`` (gave
    up: the reason is in /nav/diagnostics), ``reached`` or ``fault`` (the hardware
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


class NavDiagnostics(Message):
    """Why the navigator commanded what it did, each step (topic /nav/diagnostics)."""

    ros_type: ClassVar[str] = "otonav_msgs/msg/NavDiagnostics"
    header: Header = Header()
    planner: str = ""
    """``stop`` (go-to-goal + guard) or ``dwa``."""
    state: str = ""
    """The /nav/state of the same step."""
    reason: str = ""
    """Why, in a few words (e.g. ``avoiding``, ``follow: moved under 0.3 m in 4 s``)."""
    stage: str = ""
    """Recovery stage running (``spin``, ``backup``, ``follow``), empty if none."""
    v: float = 0.0
    """m/s, the commanded forward speed (before the safety layer)."""
    omega: float = 0.0
    """rad/s, the commanded yaw rate (before the safety layer)."""
    admissible: int = 0
    """DWA samples that could stop before breaking the clearance."""
    samples: int = 0
    """DWA samples rolled out (0: no DWA this step)."""
    best_score: float = 0.0
    """The chosen sample's score (-inf when none was admissible)."""
    clearance: float = 0.0
    """m, the chosen rollout's smallest centre clearance (map lower bound)."""
    path_length: float = 0.0
    """m, length of the current global path (NaN with none)."""
    replans: int = 0
    """Global plans made since the start."""


class SafetyState(Message):
    """What the safety layer did to a command (topic /safety/state)."""

    ros_type: ClassVar[str] = "otonav_msgs/msg/SafetyState"
    header: Header = Header()
    reason: str = ""
    """``clear``, ``safe``, ``limited``, ``stopped``, ``blind`` (no fresh scan or
    odometry: stop) or ``idle`` (no command: stop)."""
    scale: float = 1.0
    """The forward-speed scale applied (1: untouched)."""
    nearest: float = 0.0
    """m, robot centre to the nearest return (inf if none; a lower bound when
    ``clear``: the last scan's nearest less the distance driven since)."""
    v_in: float = 0.0
    omega_in: float = 0.0
    v_out: float = 0.0
    omega_out: float = 0.0


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
    nav_state: str = ""
    """The navigator's last state (reached, unreachable, ...)."""
    nav_reason: str = ""
    """The navigator's last reason, e.g. why it gave up."""
