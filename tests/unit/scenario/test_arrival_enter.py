"""``arrival: enter`` (issue 42, BARN's criterion): the first entry into the tolerance
is arriving, and the run ends there; ``arrival: stop`` (the default) still wants the
robot stopped there, the navigator saying ``reached``, 2 s later."""

from __future__ import annotations

import pytest

from otonav.scenario import run_scenario
from otonav.scenario._config import GoalSpec, ScenarioConfig
from otonav.stack import StackConfig

pytestmark = pytest.mark.unit


def _run(arrival: str) -> tuple[float, float | None, bool]:
    scenario = ScenarioConfig(
        name=f"arrive_{arrival}",
        scene="empty",
        goal=GoalSpec(x=3.0, y=0.0),
        goal_tolerance=1.0,
        arrival=arrival,  # type: ignore[arg-type]
    )
    verdict = run_scenario(scenario, StackConfig(), record=False, plot=False)
    assert verdict.passed, verdict.reason
    return verdict.sim_time_s, verdict.time_to_goal_s, verdict.reached


def test_entering_the_circle_is_arriving_and_ends_the_run() -> None:
    end, entered, reached = _run("enter")
    assert reached
    assert entered is not None
    assert entered == pytest.approx(end, abs=0.02)  # the run ends on the entry (100 Hz)
    end_stop, entered_stop, _ = _run("stop")
    assert entered_stop == entered  # the same drive, the same first entry
    assert end_stop >= entered + 2.0  # but "stop" waits for the settle check


def test_arrival_is_validated() -> None:
    with pytest.raises(ValueError, match="arrival"):
        ScenarioConfig(arrival="touch")  # type: ignore[arg-type]
