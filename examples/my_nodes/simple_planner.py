"""A user's node: the simplest planner that drives to the goal, written outside otonav.

It subscribes to /odom and /goal, publishes /cmd_vel_nav (behind otonav's safety
layer) and /nav/state (so a scenario's judge knows when it thinks it arrived), at
``Params.rate_hz`` of sim time. Launch it with this folder's ``stack.yaml``:

    otonav run --scenario empty --config examples/my_nodes/stack.yaml
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from pydantic import BaseModel, ConfigDict, Field

from otonav.msgs import Header, NavState, Odometry, PoseStamped, Time, Twist, Vector3
from otonav.runtime import LATCHED_QOS, SENSOR_DATA_QOS, Actor, Input, Output, QoS


class StraightToGoal(Actor):
    """Turn toward the goal, then drive at it; stop within ``tolerance`` (by odometry)."""

    class Params(BaseModel):
        model_config = ConfigDict(extra="forbid")

        max_v: float = Field(0.3, gt=0.0, le=2.0)
        """m/s, the top forward speed."""
        kp_ang: float = Field(2.0, gt=0.0)
        """rad/s per rad of heading error."""
        tolerance: float = Field(0.08, gt=0.0)
        """m: stop this close to the goal."""
        rate_hz: float = Field(20.0, gt=0.0, le=1000.0)

    odom = Input("/odom", Odometry, SENSOR_DATA_QOS)
    goal = Input("/goal", PoseStamped, LATCHED_QOS)
    cmd = Output("/cmd_vel_nav", Twist, QoS(depth=10))
    state = Output("/nav/state", NavState, QoS(depth=10))

    def __init__(
        self,
        params: Params | None = None,
        *,
        name: str | None = None,
        remap: Mapping[str, str] | None = None,
    ) -> None:
        super().__init__(name, remap=remap)
        self.params = params or self.Params()

    async def run(self) -> None:
        p = self.params
        rate = self.clock.rate(p.rate_hz)
        target: tuple[float, float] | None = None
        pose = (0.0, 0.0, 0.0)
        while True:
            await rate.sleep()
            if (odom := self.odom.take_latest()) is not None:
                q = odom.pose.pose.orientation
                yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
                pose = (odom.pose.pose.position.x, odom.pose.pose.position.y, yaw)
            if (goal := self.goal.take_latest()) is not None:
                target = (goal.pose.position.x, goal.pose.position.y)
            if target is None:
                continue
            dx, dy = target[0] - pose[0], target[1] - pose[1]
            distance = math.hypot(dx, dy)
            error = math.atan2(
                math.sin(math.atan2(dy, dx) - pose[2]), math.cos(math.atan2(dy, dx) - pose[2])
            )
            if distance < p.tolerance:
                v, w, what = 0.0, 0.0, "reached"
            else:
                v = p.max_v * max(0.0, math.cos(error)) * min(1.0, distance / 0.5)
                w, what = p.kp_ang * error, "driving"
            await self.cmd.publish(Twist(linear=Vector3(x=v), angular=Vector3(z=w)))
            stamp = Header(stamp=Time.from_seconds(self.clock.now()), frame_id="odom")
            await self.state.publish(
                NavState(header=stamp, state=what, distance_to_goal=distance, heading_error=error)
            )
