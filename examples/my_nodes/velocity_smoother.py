"""A user's filter between the navigator and the safety layer, as Nav2 puts its
velocity_smoother before the collision_monitor: /cmd_vel_raw in, /cmd_vel_nav out,
capped and rate-limited in sim time. Launched by this folder's ``smoothed.yaml``:

    otonav run --config examples/my_nodes/smoothed.yaml

The built-in navigator is remapped there to publish /cmd_vel_raw; the safety layer
still has the last word on /cmd_vel.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from otonav.msgs import Twist, Vector3
from otonav.runtime import Actor, Input, Output, QoS


def _step(target: float, last: float, limit: float) -> float:
    """``target``, moved from ``last`` by at most ``limit``."""
    return last + max(-limit, min(limit, target - last))


class VelocitySmoother(Actor):
    """Caps speed and acceleration, the way Nav2's velocity_smoother does."""

    class Params(BaseModel):
        model_config = ConfigDict(extra="forbid")

        max_v: float = Field(0.4, gt=0.0, le=2.0)
        """m/s, forward and back."""
        max_omega: float = Field(1.5, gt=0.0, le=10.0)
        """rad/s."""
        max_accel: float = Field(1.0, gt=0.0)
        """m/s², per command."""
        max_alpha: float = Field(3.0, gt=0.0)
        """rad/s², per command."""

    params: Params  # set by Actor.__init__ (no __init__ needed here)

    raw = Input("/cmd_vel_raw", Twist, QoS(depth=10))
    smoothed = Output("/cmd_vel_nav", Twist, QoS(depth=10))

    async def run(self) -> None:
        p = self.params
        v = omega = 0.0
        last = self.clock.now()
        async for cmd in self.raw:
            now = self.clock.now()
            dt = max(now - last, 1e-3)
            last = now
            v = _step(max(-p.max_v, min(p.max_v, cmd.linear.x)), v, p.max_accel * dt)
            omega = _step(
                max(-p.max_omega, min(p.max_omega, cmd.angular.z)), omega, p.max_alpha * dt
            )
            if v != cmd.linear.x or omega != cmd.angular.z:
                self.log.debug(
                    "smoothed (%.2f, %.2f) to (%.2f, %.2f)", cmd.linear.x, cmd.angular.z, v, omega
                )
            await self.smoothed.publish(Twist(linear=Vector3(x=v), angular=Vector3(z=omega)))
