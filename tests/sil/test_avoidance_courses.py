"""Layer 3: every built-in avoidance course (``otonav scenarios``) passes with the
default stack: the goal reached inside its budget with the robot centre never closer
than 0.3 m to a box or wall (ground truth), or, for the walled-in goal, ``unreachable``
reported inside the budget, with the same clearance. A failure keeps the recording
(``otonav_artifacts``). The stop-only navigator fails them: the courses have teeth."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.scenario import ScenarioConfig, run_scenario
from otonav.scenario._builtin import AVOIDANCE, BOX, WALLED_IN
from otonav.stack import StackConfig
from otonav.stack._overrides import apply_overrides

pytestmark = pytest.mark.sil


@pytest.mark.parametrize("scenario", AVOIDANCE, ids=[s.name for s in AVOIDANCE])
def test_course_passes_with_the_default_stack(
    scenario: ScenarioConfig, otonav_artifacts: Path
) -> None:
    verdict = run_scenario(scenario, out_dir=otonav_artifacts, plot=False, wall_ceiling=120)
    assert verdict.passed, verdict.reason
    assert verdict.min_clearance_m >= scenario.min_clearance
    if scenario.expect == "reached":
        assert verdict.reached
        assert verdict.time_to_goal_s is not None
        assert verdict.time_to_goal_s <= scenario.sim_budget
        assert verdict.final_distance_m <= scenario.goal_tolerance
    else:
        assert not verdict.reached
        assert verdict.unreachable_at_s is not None
        assert verdict.unreachable_at_s <= scenario.sim_budget
        # the run ends when the navigator gives up, not at the budget
        assert verdict.sim_time_s < scenario.sim_budget


STOP_ONLY = apply_overrides(StackConfig(), ["nav.planner=stop"])


def test_teeth_the_stop_only_navigator_waits_at_the_box_until_the_budget_ends() -> None:
    verdict = run_scenario(BOX, STOP_ONLY, record=False, plot=False, wall_ceiling=120)
    assert not verdict.passed
    assert not verdict.reached
    assert verdict.sim_time_s == pytest.approx(BOX.sim_budget, abs=0.01)
    assert "did not reach the goal" in verdict.reason


def test_teeth_a_navigator_that_never_gives_up_fails_the_walled_in_goal() -> None:
    verdict = run_scenario(WALLED_IN, STOP_ONLY, record=False, plot=False, wall_ceiling=120)
    assert not verdict.passed
    assert verdict.unreachable_at_s is None
    assert "did not report the goal unreachable within 80 s" in verdict.reason
