"""A plain rclpy node that reads and sets otonav's parameters as ``ros2 param`` does,
through rclpy's ``AsyncParameterClient`` (no otonav import).

    python param_peer.py NODE NAME VALUE AT_SIM_S

Prints ``ready`` once NODE's parameter services are there, then, once its ROS time
(use_sim_time) has passed AT_SIM_S: sets NAME to VALUE, and tries what must be refused (a
negative value, a string, a parameter that does not exist, a read-only one). Prints one
JSON line: the names listed, the results, NAME's value read back, and the ROS time when
the set had been answered.
"""

from __future__ import annotations

import json
import sys
from typing import Any

import rclpy
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient


def main() -> None:
    target, name, value, at = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
    rclpy.init()
    node = Node("param_peer", parameter_overrides=[Parameter("use_sim_time", value=True)])
    client = AsyncParameterClient(node, target)

    def wait(future: Any) -> Any:
        rclpy.spin_until_future_complete(node, future, timeout_sec=30.0)
        return future.result()

    if not client.wait_for_services(timeout_sec=60.0):
        print(json.dumps({"error": f"no parameter services of /{target}"}), flush=True)
        return
    names = list(wait(client.list_parameters()).result.names)
    print("ready", flush=True)
    while node.get_clock().now().nanoseconds < at * 1e9:
        rclpy.spin_once(node, timeout_sec=0.05)

    def set_one(key: str, val: Any) -> dict[str, Any]:
        (result,) = wait(client.set_parameters([Parameter(key, value=val)])).results
        return {"successful": result.successful, "reason": result.reason}

    report: dict[str, Any] = {"names": names, "set": set_one(name, value)}
    report["set_at"] = node.get_clock().now().nanoseconds / 1e9
    report["negative"] = set_one(name, -1.0)
    report["string"] = set_one(name, "fast")
    report["missing"] = set_one("params.no_such_parameter", 1.0)
    read_only = next((n for n in names if n.startswith("params.map")), None)
    if read_only is not None:
        report["read_only"] = set_one(read_only, 1.0)
    (read_back,) = wait(client.get_parameters([name])).values
    report["value"] = read_back.double_value
    print(json.dumps(report), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()


if __name__ == "__main__":
    main()
