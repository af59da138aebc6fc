"""The safety layer does not trust the planner: planners that drive straight at a wall or
a box at full speed, turn into a box on an arc, reverse into a wall, or spin beside a
box must all leave the judge's minimum clearance (robot centre to every obstacle
surface, ground truth) at or above 0.3 m. Each run is recorded (kept on failure)."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.actors import topics
from otonav.msgs import Twist, Vector3
from otonav.runtime import Actor, Output
from otonav.scenario import GoalSpec, ScenarioConfig, StartSpec, run_scenario
from otonav.scenario._config import BoxSpec
from otonav.stack import NavConfig, SafetyConfig, StackConfig

pytestmark = pytest.mark.sil


class Reckless(Actor):
    """A sabotaged planner: the same (v, omega) on /cmd_vel_nav at 20 Hz, whatever it sees."""

    cmd = Output(topics.CMD_VEL_NAV, Twist, topics.COMMAND_QOS)

    def __init__(self, v: float, omega: float, *, direct: bool = False) -> None:
        # direct: publish /cmd_vel itself (when there is no safety layer to go through)
        super().__init__("reckless", remap={topics.CMD_VEL_NAV: topics.CMD_VEL} if direct else None)
        self.v, self.omega = v, omega

    async def run(self) -> None:
        rate = self.clock.rate(20.0)
        while True:
            await rate.sleep()
            await self.cmd.publish(Twist(linear=Vector3(x=self.v), angular=Vector3(z=self.omega)))


EXTERNAL = StackConfig(nav=NavConfig(planner="external"))
BOX = BoxSpec(x=1.5, y=0.0, size_x=0.4, size_y=0.4)
WALL = BoxSpec(x=1.5, y=0.0, size_x=0.2, size_y=4.0)
# Far goal: these runs are about clearance, the goal only has to be valid.
FAR = GoalSpec(x=-3.5, y=3.5)
CASES = {
    # name: (obstacles, start, v, omega)
    "wall_straight": ((WALL,), StartSpec(), 2.0, 0.0),
    "box_straight": ((BOX,), StartSpec(), 2.0, 0.0),
    "box_arc": ((BOX,), StartSpec(x=0.0, y=-0.7), 0.5, 0.5),
    "wall_reverse": ((WALL,), StartSpec(x=2.4, y=0.0), -2.0, 0.0),
    "box_spin": ((BOX,), StartSpec(x=1.5, y=-0.56, yaw=0.0), 0.0, 3.0),
    "box_spin_creep": ((BOX,), StartSpec(x=1.5, y=-0.6, yaw=1.2), 0.1, 3.0),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_reckless_planner_never_breaks_the_clearance(case: str, otonav_artifacts: Path) -> None:
    obstacles, start, v, omega = CASES[case]
    scenario = ScenarioConfig(
        name=f"sabotage_{case}", scene="empty", obstacles=obstacles, start=start, goal=FAR,
        sim_budget=6.0,
    )  # fmt: skip
    verdict = run_scenario(
        scenario,
        EXTERNAL,
        out_dir=otonav_artifacts,
        plot=False,
        extra_actors=(Reckless(v, omega),),
        wall_ceiling=120,
    )
    assert verdict.recording is not None
    assert Path(verdict.recording).stat().st_size > 10_000
    assert verdict.sim_time_s == pytest.approx(6.0, abs=0.02)
    assert verdict.min_clearance_m >= 0.3, f"{case}: {verdict.min_clearance_m:.3f} m"


def test_without_the_safety_layer_the_reckless_planner_hits_the_wall(
    otonav_artifacts: Path,
) -> None:
    """The sabotage has teeth: with the layer off the same planner breaks the clearance."""
    obstacles, start, v, omega = CASES["wall_straight"]
    scenario = ScenarioConfig(
        name="sabotage_unguarded", scene="empty", obstacles=obstacles, start=start, goal=FAR,
        sim_budget=6.0,
    )  # fmt: skip
    unguarded = EXTERNAL.model_copy(update={"safety": SafetyConfig(enabled=False)})
    verdict = run_scenario(
        scenario,
        unguarded,
        out_dir=otonav_artifacts,
        plot=False,
        extra_actors=(Reckless(v, omega, direct=True),),
        wall_ceiling=120,
    )
    assert verdict.min_clearance_m < 0.3
