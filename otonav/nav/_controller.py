"""The controller (Nav2's controller server with its goal checker): one goal's command
toward the global path's target, no I/O. Units: m, s, rad; poses in odom.

* reached latches (Nav2's stateful goal checker): within ``tolerance`` the goal is
  reached, and stays so until the robot is pushed twice as far (settling or drifting a
  few mm back out must not restart the approach);
* within ``approach_radius`` of the goal a proportional controller finishes, forward or
  in reverse (an overshoot is backed out of, not turned around);
* farther away, **DWA** (:mod:`otonav.nav._dwa`) toward the target: ``driving``, or
  ``avoiding`` when the chosen arc passes near a return; ``blocked`` when no arc is
  admissible. Its distances are exact to the latest scan's returns near the robot, the
  map's elsewhere (:mod:`otonav.nav._local_clearance`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from otonav.nav._dwa import ClearanceFn, DwaResult, clear_arc, dwa_step
from otonav.nav._geometry import wrap_angle
from otonav.nav._local_clearance import local_clearance, nearby
from otonav.nav._planner import GlobalPlanner
from otonav.params import NavigationParams

__all__ = ("Command", "Controller")

Command = tuple[float, float, str, str, DwaResult | None]
"""v m/s, omega rad/s, state, reason, the DWA's result (None: the final approach)."""


@dataclass(slots=True)
class Controller:
    """One goal's controller: the goal checker's latch (a new goal: a new one)."""

    reached: bool = False

    def arrived(self, distance: float, tolerance: float) -> bool:
        """Within ``tolerance``, or twice that once reached (the latch), m."""
        self.reached = distance <= tolerance or (self.reached and distance <= 2.0 * tolerance)
        return self.reached

    def command(
        self,
        pose: tuple[float, float, float],
        v0: float,
        omega0: float,
        target: tuple[float, float],
        distance: float,
        heading: float,
        planner: GlobalPlanner,
        p: NavigationParams,
    ) -> Command:
        """The command toward ``target`` (``distance``, ``heading``: of the goal)."""
        dwa, clearance_map = p.dwa, planner.map
        if distance < p.approach_radius:
            # The last centimetres: P-control on distance and heading, in reverse when
            # the goal is behind; the safety layer still checks every command.
            ahead = abs(heading) <= math.pi / 2
            facing = heading if ahead else wrap_angle(heading - math.pi)
            v_max = min(dwa.max_v, math.sqrt(dwa.max_accel * distance))
            v = min(p.kp_lin * distance, v_max) * math.cos(facing) * (1.0 if ahead else -1.0)
            omega = min(max(p.kp_ang * facing, -dwa.max_omega), dwa.max_omega)
            return v, omega, "driving", "final approach", None
        result = (
            clear_arc(pose, v0, omega0, target, distance, clearance_map.clearance_at, dwa)
            if dwa.fast_path
            else None
        )
        if result is None:
            clearance: ClearanceFn = clearance_map.clearance
            if planner.returns is not None:
                reach = dwa.max_v * dwa.horizon + dwa.radius + 0.1
                rx, ry = nearby(*planner.returns, pose[0], pose[1], reach)
                clearance = local_clearance(clearance, clearance_map.slack, dwa.radius, rx, ry)
            result = dwa_step(pose, v0, omega0, target, distance, clearance, dwa)
        if result.admissible == 0:
            state = "blocked"
        else:
            state = "avoiding" if result.reason == "avoiding" else "driving"
        return result.v, result.omega, state, result.reason, result
