"""A plain rclpy node that subscribes as ROS 2 users write it (no otonav import).

    python qos_peer.py SIM_SECONDS

``/odom`` with the default QoS (``10``: reliable), ``/scan`` and ``/imu`` with
``qos_profile_sensor_data``, and ``/clock`` through ``use_sim_time`` (tf2_msgs is not on
PyPI: /tf is left out). Prints ``ready``
once its subscriptions exist, then one JSON line once its ROS time has passed
SIM_SECONDS: the samples per topic, the QoS incompatibilities rclpy reported, its ROS
time, and the graph (``get_node_names_and_namespaces``, publishers by node).
"""

from __future__ import annotations

import json
import sys
from typing import Any

import rclpy
from nav_msgs.msg import Odometry
from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import qos_profile_sensor_data
from sensor_msgs.msg import Imu, LaserScan


def main() -> None:
    until = float(sys.argv[1])
    rclpy.init()
    node = Node("qos_peer", parameter_overrides=[Parameter("use_sim_time", value=True)])
    counts = {"/odom": 0, "/scan": 0, "/imu": 0}
    problems: list[str] = []

    def count(topic: str) -> Any:
        def callback(_msg: Any) -> None:
            counts[topic] += 1

        return callback

    def events(topic: str) -> SubscriptionEventCallbacks:
        return SubscriptionEventCallbacks(
            incompatible_qos=lambda e: problems.append(f"{topic}: {e.last_policy_kind}"),
            incompatible_type=lambda _e: problems.append(f"{topic}: incompatible type"),
        )

    subscriptions = [
        ("/odom", Odometry, 10),
        ("/scan", LaserScan, qos_profile_sensor_data),
        ("/imu", Imu, qos_profile_sensor_data),
    ]
    for topic, kind, qos in subscriptions:
        node.create_subscription(kind, topic, count(topic), qos, event_callbacks=events(topic))
    print("ready", flush=True)
    while node.get_clock().now().nanoseconds < until * 1e9:
        rclpy.spin_once(node, timeout_sec=0.1)
    by_node = {
        f"{ns.rstrip('/')}/{name}": sorted(
            topic for topic, _types in node.get_publisher_names_and_types_by_node(name, ns)
        )
        for name, ns in node.get_node_names_and_namespaces()
        if name != "qos_peer"
    }
    report = {
        "counts": counts,
        "problems": problems,
        "ros_time": node.get_clock().now().nanoseconds / 1e9,
        "nodes": by_node,
    }
    print(json.dumps(report), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()


if __name__ == "__main__":
    main()
