"""A scenario's ``expect``: the judge follows /nav/state, and the verdict passes when
the expected outcome happened (the goal reached, or ``unreachable`` reported inside the
budget) with the clearance held, and says why not otherwise."""

from __future__ import annotations

import math
from pathlib import Path

import anyio
import pytest

from otonav.actors import topics
from otonav.hal import BoxObstacle, FakeHardware
from otonav.msgs import NavState
from otonav.runtime import System, virtual_loop_factory
from otonav.scenario import Judge, ScenarioConfig
from otonav.scenario._verdict import judge_verdict
from otonav.stack._files import ConfigFileError, load_model

pytestmark = pytest.mark.unit

WALLED = ScenarioConfig(name="walled", scene="empty", sim_budget=10.0, expect="unreachable")
OPEN = ScenarioConfig(name="open", scene="empty", sim_budget=10.0)


def _judge_states(states: list[tuple[float, str]], *, duration: float = 3.0) -> Judge:
    """Run a judge (robot standing still at the origin, a box 1 m ahead) while /nav/state
    carries ``states`` at the given sim times; return it."""
    hal = FakeHardware(obstacles=[BoxObstacle(1.0, 0.0, 0.1, 0.1)])
    judge = Judge(hal, (4.0, 0.0), 0.15)

    async def main() -> None:
        async with System([judge]) as system:
            pub = system.publisher(topics.NAV_STATE, NavState, name="nav")
            for at, state in states:
                await anyio.sleep(at - anyio.current_time())
                await pub.publish(NavState(state=state))
            await anyio.sleep(duration - anyio.current_time())

    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory(hal, wall_ceiling=10)})
    return judge


def test_the_judge_notes_when_nav_first_says_unreachable() -> None:
    judge = _judge_states([(0.5, "driving"), (1.2, "recovering"), (1.5, "unreachable")])
    assert judge.unreachable_at == pytest.approx(1.5, abs=0.011)  # sampled at 100 Hz
    assert judge.gave_up
    assert judge.finished
    assert judge.nav_state == "unreachable"


def test_a_short_lived_unreachable_is_not_missed() -> None:
    # Two states in the same judge period: the judge drains them all.
    judge = _judge_states([(1.0, "unreachable"), (1.001, "idle")])
    assert judge.unreachable_at == pytest.approx(1.0, abs=0.011)
    assert judge.nav_state == "idle"


def test_no_unreachable_no_give_up() -> None:
    judge = _judge_states([(0.5, "driving"), (1.0, "blocked")])
    assert judge.unreachable_at is None
    assert not judge.finished


def test_expect_unreachable_passes_when_reported_in_budget_with_clearance() -> None:
    judge = _judge_states([(1.5, "unreachable")])
    verdict = judge_verdict(WALLED, judge, 1.51, 0.1)
    assert verdict.passed, verdict.reason
    assert not verdict.reached
    assert verdict.expect == "unreachable"
    assert verdict.unreachable_at_s == pytest.approx(1.5, abs=0.011)
    assert "as expected" in verdict.reason


def test_expect_unreachable_fails_on_a_timeout() -> None:
    judge = _judge_states([(0.5, "blocked")])
    verdict = judge_verdict(WALLED, judge, 10.0, 0.1)
    assert not verdict.passed
    assert "did not report the goal unreachable within 10 s" in verdict.reason
    assert "last state: blocked" in verdict.reason


def test_expect_unreachable_fails_when_the_clearance_broke() -> None:
    judge = _judge_states([(1.5, "unreachable")])
    judge.min_clearance = 0.2
    verdict = judge_verdict(WALLED, judge, 1.51, 0.1)
    assert not verdict.passed
    assert "came 0.200 m from an obstacle" in verdict.reason


def test_expect_reached_fails_when_nav_gives_up_and_says_so() -> None:
    judge = _judge_states([(1.5, "unreachable")])
    verdict = judge_verdict(OPEN, judge, 1.51, 0.1)
    assert not verdict.passed
    assert "reported the goal unreachable at 1.5 s" in verdict.reason


def test_expect_unreachable_fails_when_the_goal_is_reached() -> None:
    judge = _judge_states([])
    judge.time_to_goal = 2.0
    judge.arrival_checked_at = 4.0  # arrived: the check 2 s after entry found no problem
    verdict = judge_verdict(WALLED, judge, 2.0, 0.1)
    assert not verdict.passed
    assert "reached a goal that was expected to be unreachable" in verdict.reason


def test_expect_reached_is_unchanged() -> None:
    judge = _judge_states([])
    judge.time_to_goal = 2.0
    judge.arrival_checked_at = 4.0  # arrived: the check 2 s after entry found no problem
    assert judge.min_clearance == pytest.approx(0.9, abs=1e-6)  # the box 1 m ahead
    verdict = judge_verdict(OPEN, judge, 2.0, 0.1)
    assert verdict.passed, verdict.reason
    assert verdict.reason == "reached the goal with clearance"
    assert math.isfinite(verdict.final_distance_m)


def test_expect_in_a_file_is_validated(tmp_path: Path) -> None:
    path = tmp_path / "s.yaml"
    path.write_text("name: x\nexpect: timeout\ngoal: {x: 1.0, y: 0.0}\n")
    with pytest.raises(ConfigFileError, match=r"expect: .*'reached' or 'unreachable'"):
        load_model(path, ScenarioConfig)
    path.write_text("name: x\nexpect: unreachable\ngoal: {x: 1.0, y: 0.0}\n")
    assert load_model(path, ScenarioConfig).expect == "unreachable"
