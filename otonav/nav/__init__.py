"""Pure navigation math (no I/O, no actors): the go-to-goal controller, the obstacle
guard, the local planner (DWA), the safety limit, and the navigation that ties them
with a costmap, a global path and recovery (:class:`Navigation`)."""

from otonav.nav._dwa import DwaParams, DwaResult, dwa_step
from otonav.nav._footprint import centre_clearance
from otonav.nav._geometry import goal_problem, wrap_angle
from otonav.nav._go_to_goal import GoalCommand, GoToGoalParams, go_to_goal
from otonav.nav._guard import GuardParams, guard_blocked
from otonav.nav._navigate import Navigation, NavOutput
from otonav.nav._safety import SafetyParams, SafetyResult, safe_command
from otonav.params import NavigationParams

__all__ = (
    "DwaParams",
    "DwaResult",
    "GoToGoalParams",
    "GoalCommand",
    "GuardParams",
    "NavOutput",
    "Navigation",
    "NavigationParams",
    "SafetyParams",
    "SafetyResult",
    "centre_clearance",
    "dwa_step",
    "go_to_goal",
    "goal_problem",
    "guard_blocked",
    "safe_command",
    "wrap_angle",
)
