"""Pure navigation math: go-to-goal controller, obstacle guard, angle helpers (no I/O)."""

from otonav.nav.geometry import wrap_angle
from otonav.nav.go_to_goal import GoalCommand, GoToGoalParams, go_to_goal
from otonav.nav.guard import GuardParams, guard_blocked

__all__ = (
    "GoToGoalParams",
    "GoalCommand",
    "GuardParams",
    "go_to_goal",
    "guard_blocked",
    "wrap_angle",
)
