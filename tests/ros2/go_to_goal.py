"""An ordinary rclpy go-to-goal node, as a ROS 2 user writes one (no otonav import).

Runs in a venv with a real ROS 2 from PyPI (``make ros2-peers``: Jazzy and Kilted rclpy on
Fast DDS), in its own process:

    python go_to_goal.py --ros-args -p use_sim_time:=true

A 20 Hz timer on the node's clock reads the latest /odom (subscribed with the default QoS,
``10``: reliable) and /scan (``qos_profile_sensor_data``), turns toward the latched /goal
and drives at it, slowing when the scan sees something close ahead, and publishes
/cmd_vel_nav (Twist) on every tick: zero until it has a goal, zero once it is within
``tolerance`` of it. Parameters: ``max_v`` (m/s), ``kp_ang`` (1/s), ``tolerance`` (m),
``stamped`` (publish TwistStamped, as for Jazzy's diff_drive_controller).
"""

from __future__ import annotations

import math
import sys

import rclpy
from geometry_msgs.msg import PoseStamped, Twist, TwistStamped
from nav_msgs.msg import Odometry
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, qos_profile_sensor_data
from sensor_msgs.msg import LaserScan

PERIOD = 0.05


class GoToGoal(Node):
    def __init__(self) -> None:
        super().__init__("go_to_goal")
        self.max_v = float(self.declare_parameter("max_v", 0.35).value)
        self.kp_ang = float(self.declare_parameter("kp_ang", 2.0).value)
        self.tolerance = float(self.declare_parameter("tolerance", 0.06).value)
        self.stamped = bool(self.declare_parameter("stamped", False).value)
        self.pose: tuple[float, float, float] | None = None
        self.goal: tuple[float, float] | None = None
        self.ahead = math.inf
        self.create_subscription(Odometry, "/odom", self.on_odom, 10)
        self.create_subscription(LaserScan, "/scan", self.on_scan, qos_profile_sensor_data)
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.create_subscription(PoseStamped, "/goal", self.on_goal, latched)
        kind = TwistStamped if self.stamped else Twist
        self.cmd = self.create_publisher(kind, "/cmd_vel_nav", 10)
        self.create_timer(PERIOD, self.tick)

    def on_odom(self, msg: Odometry) -> None:
        q = msg.pose.pose.orientation
        yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        self.pose = (msg.pose.pose.position.x, msg.pose.pose.position.y, yaw)

    def on_scan(self, msg: LaserScan) -> None:
        ahead = [
            r
            for i, r in enumerate(msg.ranges)
            if abs(msg.angle_min + i * msg.angle_increment) < 0.35 and math.isfinite(r)
        ]
        self.ahead = min(ahead, default=math.inf)

    def on_goal(self, msg: PoseStamped) -> None:
        self.goal = (msg.pose.position.x, msg.pose.position.y)

    def tick(self) -> None:
        twist = Twist()
        if self.pose is not None and self.goal is not None:
            x, y, yaw = self.pose
            dx, dy = self.goal[0] - x, self.goal[1] - y
            distance = math.hypot(dx, dy)
            if distance > self.tolerance:
                error = math.atan2(dy, dx) - yaw
                error = math.atan2(math.sin(error), math.cos(error))
                slow = min(1.0, max(0.0, (self.ahead - 0.25) / 0.5))
                twist.linear.x = (
                    self.max_v * max(0.0, math.cos(error)) * min(1.0, distance / 0.5) * slow
                )
                twist.angular.z = max(-1.5, min(1.5, self.kp_ang * error))
        if self.stamped:
            stamped = TwistStamped(twist=twist)
            stamped.header.stamp = self.get_clock().now().to_msg()
            stamped.header.frame_id = "base_link"
            self.cmd.publish(stamped)
        else:
            self.cmd.publish(twist)


def main() -> None:
    rclpy.init(args=sys.argv)
    node = GoToGoal()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
