"""The navigator on the fake stack: goal handling, states, turning, the obstacle guard,
and the whole loop (FakeHardware + bridge + base + nav) reaching a goal in sim time."""

from __future__ import annotations

import asyncio
import math
from collections.abc import Callable, Coroutine, Sequence
from dataclasses import dataclass
from typing import Any

import anyio
import pytest

from otonav.actors import AvoidingNavigator, BaseController, Bridge, Navigator, topics
from otonav.control import DiffDriveGeometry
from otonav.hal import BoxObstacle, FakeHardware
from otonav.msgs import NavState, Point, Pose, PoseStamped, Twist
from otonav.nav import GuardParams, NavigationParams, goal_problem
from otonav.runtime import (
    Actor,
    Bus,
    QoS,
    Reliability,
    Subscription,
    System,
    VirtualTimeLoop,
    until,
    virtual_loop_factory,
)
from otonav.runtime._mailbox import Endpoint

pytestmark = pytest.mark.unit

OBSERVE = QoS(Reliability.BEST_EFFORT, depth=100_000)
NAV_PERIOD = 1.0 / 20.0


@dataclass(slots=True)
class Trace:
    """What the navigator said, with the sim time it said it at."""

    states: list[NavState]
    cmd_vel: list[tuple[float, Twist]]

    def collapsed(self) -> list[str]:
        """The sequence of states, repeats collapsed: e.g. ["driving", "reached"]."""
        out: list[str] = []
        for message in self.states:
            if not out or out[-1] != message.state:
                out.append(message.state)
        return out

    def first(self, state: str) -> NavState:
        return next(m for m in self.states if m.state == state)


def _goal(x: float, y: float) -> PoseStamped:
    return PoseStamped(pose=Pose(position=Point(x=x, y=y)))


def _stack(hal: FakeHardware, nav: Actor, *, base: bool = True) -> list[Actor]:
    geometry = DiffDriveGeometry(hal.geometry.wheel_radius, hal.geometry.wheel_separation)
    return [Bridge(hal), *([BaseController(geometry)] if base else []), nav]


async def _drain(sub: Subscription[Any], into: list[Any], *, timed: bool) -> None:
    async for message in sub:
        into.append((anyio.current_time(), message) if timed else message)


def _fly(
    hal: FakeHardware,
    actors: Sequence[Actor],
    *,
    duration: float,
    bus: Bus | None = None,
    during: Callable[[System], Coroutine[Any, Any, None]] | None = None,
) -> Trace:
    """Run ``actors`` for ``duration`` s of sim time on ``hal``'s clock, running
    ``during(system)`` alongside; return /nav/state and /cmd_vel."""
    trace = Trace([], [])

    async def main() -> None:
        async with System(actors, bus=bus) as system:
            states = system.subscribe(topics.NAV_STATE, NavState, OBSERVE)
            cmd_vel = system.subscribe(topics.CMD_VEL, Twist, OBSERVE)
            async with anyio.create_task_group() as tg:
                tg.start_soon(lambda: _drain(states, trace.states, timed=False))
                tg.start_soon(lambda: _drain(cmd_vel, trace.cmd_vel, timed=True))
                if during is not None:
                    tg.start_soon(during, system)
                # A hair past ``duration``: what is published at ``duration`` is in.
                await anyio.sleep(duration + 1e-3)
                tg.cancel_scope.cancel()

    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory(hal, wall_ceiling=10)})
    return trace


# -- states ------------------------------------------------------------------------------


def test_idle_without_a_goal() -> None:
    hal = FakeHardware()
    trace = _fly(hal, _stack(hal, Navigator()), duration=1.0)
    assert len(trace.states) == 20  # 20 Hz
    assert trace.collapsed() == ["idle"]
    assert all(m.distance_to_goal == math.inf for m in trace.states)
    assert all(t.linear.x == 0.0 and t.angular.z == 0.0 for _, t in trace.cmd_vel)
    assert hal.ground_truth().x == 0.0


def test_goal_latched_before_the_navigator_starts() -> None:
    # The goal is on /goal (transient-local) before the navigator even exists: it gets
    # it from the publisher's history when it is wired, as a late ROS 2 subscriber would.
    bus = Bus()
    goal = bus.publisher(topics.GOAL, PoseStamped, topics.LATCHED, endpoint=Endpoint("ui", "goal"))
    goal.publish_nowait(_goal(1.0, 0.0))
    hal = FakeHardware()
    trace = _fly(hal, _stack(hal, Navigator()), duration=5.0, bus=bus)
    # It waits for its first scan before driving: the guard fails safe. The scan comes
    # at 0.1 s, after the navigator's own 0.1 s tick (armed earlier, FIFO), so the first
    # tick that sees it is at 0.15 s.
    assert trace.collapsed() == ["waiting", "driving", "reached"]
    assert trace.first("waiting").header.stamp.to_seconds() == pytest.approx(NAV_PERIOD)
    assert trace.first("driving").header.stamp.to_seconds() == pytest.approx(0.15)
    reached = trace.first("reached")
    assert reached.distance_to_goal <= 0.1
    assert reached.header.stamp.to_seconds() < 4.0
    truth = hal.ground_truth()
    assert math.hypot(truth.x - 1.0, truth.y) < 0.15
    # Once there, it commands a standstill.
    t_reached = reached.header.stamp.to_seconds()
    after = [t for at, t in trace.cmd_vel if at >= t_reached]
    assert after
    assert all(t.linear.x == 0.0 and t.angular.z == 0.0 for t in after)


def test_goal_published_after_the_navigator_started() -> None:
    hal = FakeHardware()

    async def publish_goal(system: System) -> None:
        goal = system.publisher(topics.GOAL, PoseStamped, topics.LATCHED, name="ui")
        await anyio.sleep(1.0)
        await goal.publish(_goal(1.0, 0.0))

    trace = _fly(hal, _stack(hal, Navigator()), duration=5.0, during=publish_goal)
    assert trace.collapsed() == ["idle", "driving", "reached"]
    started = trace.first("driving").header.stamp.to_seconds()
    assert 1.0 <= started <= 1.0 + NAV_PERIOD + 1e-9
    assert math.hypot(hal.ground_truth().x - 1.0, hal.ground_truth().y) < 0.15


@pytest.mark.parametrize(("goal_y", "sign"), [(1.0, 1.0), (-1.0, -1.0)], ids=["left", "right"])
def test_turns_toward_the_goal(goal_y: float, sign: float) -> None:
    hal = FakeHardware()
    trace = _fly(hal, _stack(hal, Navigator(goal=(0.0, goal_y))), duration=0.5)
    _, first = trace.cmd_vel[0]
    # 90 degrees off: turn in place toward it (CCW, omega > 0, for a goal on the left).
    assert first.linear.x == 0.0
    assert sign * first.angular.z > 0.0
    assert sign * trace.states[0].heading_error == pytest.approx(math.pi / 2)
    assert sign * hal.ground_truth().yaw > 0.2  # the robot really turned that way
    assert abs(hal.ground_truth().x) < 1e-9  # in place


# -- the obstacle guard ------------------------------------------------------------------


def test_blocked_by_a_box_straight_ahead_within_the_guard_distance() -> None:
    # The box's face is 0.40 m ahead of base_link: 0.34 m from the laser (0.06 m ahead),
    # inside the 0.35 m stop distance. The goal is behind it.
    box = BoxObstacle(0.5, 0.0, 0.1, 0.5)
    hal = FakeHardware(obstacles=[box])
    trace = _fly(hal, _stack(hal, Navigator(goal=(2.0, 0.0))), duration=2.0)
    assert trace.collapsed()[-1] == "blocked"
    blocked = trace.first("blocked")
    assert blocked.closest_ahead == pytest.approx(0.34, abs=0.01)
    # From the first scan on (10 Hz), it is blocked and stays blocked.
    assert blocked.header.stamp.to_seconds() <= 0.1 + 2 * NAV_PERIOD + 1e-9
    assert all(m.state == "blocked" for m in trace.states if m.header.stamp.to_seconds() >= 0.2)
    after = [t for at, t in trace.cmd_vel if at >= blocked.header.stamp.to_seconds()]
    assert all(t.linear.x == 0.0 and t.angular.z == 0.0 for t in after)
    truth = hal.ground_truth()
    assert truth.vx_world == 0.0
    assert truth.x < 0.05
    assert box.distance_to(truth.x, truth.y) > 0.3


def test_drives_then_stops_blocked_short_of_a_box() -> None:
    box = BoxObstacle(1.8, 0.0, 0.1, 0.5)
    guard = GuardParams(stop_distance=0.35)
    hal = FakeHardware(obstacles=[box])
    trace = _fly(hal, _stack(hal, Navigator(guard=guard, goal=(3.0, 0.0))), duration=5.0)
    assert trace.collapsed() == ["waiting", "driving", "blocked"]
    assert trace.first("blocked").closest_ahead <= guard.stop_distance
    truth = hal.ground_truth()
    assert truth.vx_world == 0.0
    assert truth.x > 1.0  # it drove first
    assert box.distance_to(truth.x, truth.y) > 0.15  # and stopped without contact


def test_a_box_beside_the_path_does_not_block() -> None:
    box = BoxObstacle(1.0, 0.8, 0.2, 0.2)  # well outside the front sector
    hal = FakeHardware(obstacles=[box])
    trace = _fly(hal, _stack(hal, Navigator(goal=(2.0, 0.0))), duration=6.0)
    assert "blocked" not in trace.collapsed()
    assert trace.collapsed()[-1] == "reached"


# -- the whole loop ----------------------------------------------------------------------


@pytest.mark.sim(wall_ceiling=10)
@pytest.mark.parametrize("goal", [(2.0, 0.0), (1.2, -1.6)], ids=["ahead", "behind-right"])
async def test_fake_stack_reaches_a_goal_two_metres_away(goal: tuple[float, float]) -> None:
    loop = asyncio.get_running_loop()
    assert isinstance(loop, VirtualTimeLoop)
    hal = FakeHardware()  # odom and world frames coincide at the start
    loop.attach_source(hal)  # the fake world is now the clock
    start = loop.time()
    async with System(_stack(hal, Navigator(goal=goal))) as system:
        states = system.subscribe(topics.NAV_STATE, NavState, QoS(Reliability.BEST_EFFORT, 1))
        last: list[NavState] = []

        def reached() -> bool:
            message = states.take_latest()
            if message is not None:
                last[:] = [message]
            return bool(last) and last[0].state == "reached"

        await until(reached, within=8.0, what="goal reached", observe=lambda: last)
        elapsed = loop.time() - start
    truth = hal.ground_truth()
    assert math.hypot(truth.x - goal[0], truth.y - goal[1]) < 0.15
    # 2 m at <= 0.5 m/s with a proportional slow-down and (for the second) a turn first.
    assert 4.0 < elapsed < 8.0


def test_rate_must_be_positive() -> None:
    with pytest.raises(ValueError, match="rate_hz"):
        Navigator(rate_hz=0.0)


def test_a_scan_that_stops_arriving_makes_it_wait_after_scan_timeout() -> None:
    """The guard fails safe when the lidar goes silent, not only before the first scan."""
    from otonav.msgs import LaserScan, Odometry

    states: list[tuple[float, str]] = []

    async def main() -> None:
        nav = Navigator(goal=(5.0, 0.0), scan_timeout=0.5)
        async with System([nav]) as system:
            odom = system.publisher(topics.ODOM, Odometry, topics.SENSOR_QOS)
            scan = system.publisher(topics.SCAN, LaserScan, topics.SENSOR_QOS)
            watch = system.subscribe(topics.NAV_STATE, NavState, OBSERVE)
            far = LaserScan(
                angle_min=-math.pi,
                angle_increment=2 * math.pi / 8,
                range_max=8.0,
                ranges=(5.0,) * 8,
            )
            for k in range(40):  # odometry keeps coming; the lidar stops after 1 s
                await odom.publish(Odometry())
                if k < 10:
                    await scan.publish(far)
                await system.clock.sleep(0.1)
            while (m := watch.try_recv()) is not None:
                states.append((m.header.stamp.to_seconds(), m.state))

    anyio.run(main, backend_options={"loop_factory": virtual_loop_factory()})
    driving = [t for t, s in states if s == "driving"]
    waiting_after = [t for t, s in states if s == "waiting" and t > 1.0]
    assert driving
    assert max(driving) <= 0.9 + 0.5 + NAV_PERIOD
    assert waiting_after
    assert min(waiting_after) > 0.9 + 0.5 - 1e-9
    assert all(s == "waiting" for t, s in states if t > 0.9 + 0.5 + NAV_PERIOD)


# -- goals it refuses (defence in depth behind the door, issue 41) ---------------------


@pytest.mark.parametrize("kind", ["stop", "dwa"])
def test_a_goal_off_the_world_on_goal_is_refused_and_the_old_goal_kept(kind: str) -> None:
    # Published on the bus directly (no door in front): NaN, inf and 1e308 crashed the
    # avoiding navigator's map lookup (_coarse_cell), 1e308 the go-to-goal's arithmetic.
    bad = (math.nan, math.inf, -math.inf, 1e308, 1000.5)
    hal = FakeHardware()
    nav: Navigator | AvoidingNavigator = (
        Navigator() if kind == "stop" else AvoidingNavigator(NavigationParams(), laser_offset_x=0.0)
    )

    async def publish_goals(system: System) -> None:
        goal = system.publisher(topics.GOAL, PoseStamped, topics.LATCHED, name="ui")
        await goal.publish(_goal(1.0, 0.0))
        for x in bad:
            await anyio.sleep(0.1)
            await goal.publish(_goal(x, 0.0) if x != 1000.5 else _goal(0.0, -x))

    trace = _fly(hal, _stack(hal, nav), duration=6.0, during=publish_goals)
    assert nav.refused_goals == len(bad)
    assert trace.collapsed()[-1] == "reached"
    assert math.hypot(hal.ground_truth().x - 1.0, hal.ground_truth().y) < 0.15


@pytest.mark.parametrize(
    ("x", "y", "ok"),
    [(0.0, 0.0, True), (-1000.0, 1000.0, True), (math.nan, 0.0, False), (0.0, math.inf, False),
     (1e308, 0.0, False), (0.0, -1000.001, False)],
)  # fmt: skip
def test_goal_problem_bounds_a_goal_as_a_scenario_bounds_it(x: float, y: float, ok: bool) -> None:
    problem = goal_problem(x, y)
    assert (problem is None) is ok
    if not ok:
        assert problem is not None
        assert "[-1000, 1000]" in problem
