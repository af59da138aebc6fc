"""The stack's topic names and QoS, in one place (like a ROS 2 interface package)."""

from __future__ import annotations

from dataclasses import dataclass

from otonav.runtime import LATCHED_QOS, SENSOR_DATA_QOS, Durability, QoS, Reliability

CLOCK = "/clock"
ODOM = "/odom"
IMU = "/imu"
SCAN = "/scan"
JOINT_STATES = "/joint_states"
TF = "/tf"
TF_STATIC = "/tf_static"
#: The localizer's map (nav_msgs/OccupancyGrid, latched).
MAP = "/map"
CMD_VEL = "/cmd_vel"
#: The planner's command, before the safety layer (Nav2: cmd_vel_nav -> collision monitor).
CMD_VEL_NAV = "/cmd_vel_nav"
WHEEL_CMD = "/wheel_cmd"
GOAL = "/goal"
NAV_STATE = "/nav/state"
NAV_DIAGNOSTICS = "/nav/diagnostics"
SAFETY_STATE = "/safety/state"
ROSOUT = "/rosout"
#: What a node's parameters became (rcl_interfaces/ParameterEvent).
PARAMETER_EVENTS = "/parameter_events"
HARDWARE_STATUS = "/hardware/status"
DIAGNOSTICS = "/diagnostics"


@dataclass(frozen=True, slots=True)
class Frames:
    """The frame ids the sensor bridge stamps (/odom's child, /tf, /tf_static, /scan,
    /imu), as a ROS 2 robot's URDF names its links (REP 105). ``odom`` stays ``odom``."""

    base: str = "base_link"
    laser: str = "laser"
    imu: str = "imu_link"


#: The frame ids of otonav's own robot (a robot config's ``robot.frames`` renames them).
FRAMES = Frames()

#: Sensor streams: best-effort, keep a few (a slow reader sees the newest, never stalls physics).
SENSOR_QOS = SENSOR_DATA_QOS
#: /odom: reliable, keep the last 10, as diff_drive_controller offers it: a node written
#: ``create_subscription(Odometry, "/odom", cb, 10)`` asks reliable and matches only this
#: (issue 37). The stack's own readers still subscribe best effort (SENSOR_QOS).
ODOM_QOS = QoS(depth=10)
#: /clock: best-effort, keep the last one.
CLOCK_QOS = QoS(Reliability.BEST_EFFORT, depth=1)
#: Commands and state: reliable.
COMMAND_QOS = QoS(depth=10)
#: /tf: reliable with room for a slow recorder, as in ROS 2 (depth 100).
TF_QOS = QoS(depth=100)
#: Goals and static transforms: latched (a late subscriber gets the last one).
LATCHED = LATCHED_QOS
#: /hardware/status: reliable, latched, a few deep (published on change only).
HARDWARE_QOS = QoS(depth=10, durability=Durability.TRANSIENT_LOCAL)
#: /diagnostics: periodic and for people: best-effort, never holds the bridge back.
DIAGNOSTICS_QOS = QoS(Reliability.BEST_EFFORT, depth=10)
#: /rosout: as in ROS 2, reliable, keep the last 1000.
ROSOUT_QOS = QoS(depth=1000)
#: /parameter_events: as rclcpp's qos_profile_parameter_events, reliable, the last 1000.
PARAMETER_EVENTS_QOS = QoS(depth=1000)
