"""The robot a replay builds its actors for: the recorded geometry, read back as the same
doubles, and the world built only when something asks for more than the geometry."""

from __future__ import annotations

import json
import sys

import pytest

from otonav.hal import FakeHardware, RobotGeometry, WheelSetpoint
from otonav.hal._description import builtin_robot
from otonav.hal.mujoco import MujocoInterface
from otonav.replay import ReplayInputError
from otonav.replay._nodes import build_nodes, stack_actor_names
from otonav.replay._world import RecordedRobot
from otonav.stack import StackConfig
from otonav.stack._worldmeta import geometry_from_metadata, reach_from_metadata, world_metadata

pytestmark = pytest.mark.unit

ODD = RobotGeometry(
    wheel_radius=0.1 + 0.2,  # 0.30000000000000004: must come back as that very double
    wheel_separation=1 / 3,
    laser_offset_x=-0.0,
    laser_offset_z=1e-300,
    base_height=0.05,
    imu_offset=(0.1, -0.2, 0.3),
    footprint=((-0.5, -0.25), (0.5, -0.25), (0.5, 0.25), (-0.5, 0.25), (0.0, 0.4)),
)


class _Shaped(FakeHardware):
    @property
    def geometry(self) -> RobotGeometry:
        return ODD


def test_the_record_holds_the_geometry_the_actors_were_built_for() -> None:
    with MujocoInterface("obstacles") as world:
        record = world_metadata(world)
        assert geometry_from_metadata(record) == world.geometry
        assert "obstacles" in record
        assert "walls" in record


def test_odd_doubles_come_back_bit_for_bit() -> None:
    hal = _Shaped()
    back = geometry_from_metadata(world_metadata(hal))
    assert back == ODD
    assert back is not None
    assert back.wheel_radius.hex() == (0.1 + 0.2).hex()


@pytest.mark.parametrize(
    "robot",
    [None, "not json", "[]", json.dumps({"wheel_radius": 0.05}), json.dumps({"footprint": 3})],
)
def test_a_record_without_a_readable_geometry_gives_none(robot: str | None) -> None:
    record = {"obstacles": "[]", "walls": "[]"}
    if robot is not None:
        record["robot"] = robot
    assert geometry_from_metadata(record) is None


def test_the_world_is_built_once_and_only_when_asked_for() -> None:
    built: list[FakeHardware] = []

    def build() -> FakeHardware:
        built.append(FakeHardware())
        return built[-1]

    robot = RecordedRobot(ODD, build)
    assert robot.geometry is ODD
    assert not robot.built
    assert built == []
    robot.write(WheelSetpoint(1.0, 1.0))
    robot.advance(10)
    assert robot.built
    assert len(built) == 1
    assert robot.ticks == 10 == built[0].ticks
    assert robot.read_wheels() == built[0].read_wheels()
    assert robot.obstacles() == built[0].obstacles()
    assert robot.geometry is ODD  # still the recorded one
    assert len(built) == 1
    robot.close()
    with pytest.raises(RuntimeError, match="closed"):
        built[0].advance(1)


def test_closing_an_unbuilt_robot_builds_nothing() -> None:
    robot = RecordedRobot(ODD, lambda: pytest.fail("built"))
    robot.close()
    assert not robot.built


def test_a_can_stack_without_python_can_is_one_line(monkeypatch: pytest.MonkeyPatch) -> None:
    # The actors of a CAN recording are built for its recorded robot, no bus opened;
    # without the extra, the stack's CAN modules cannot even be imported.
    for name in [m for m in sys.modules if m == "can" or m.startswith(("can.", "otonav.hal.can"))]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "can", None)
    stack = StackConfig.model_validate({"hal": {"kind": "can"}})
    with pytest.raises(ReplayInputError, match=r"pip install 'otonav\[can\]'"):
        build_nodes(["nav"], stack, ODD)


def test_a_can_stack_replays_its_actors_without_a_bus() -> None:
    stack = StackConfig.model_validate({"hal": {"kind": "can"}})
    assert stack_actor_names(stack, ODD) == ["base", "nav", "safety"]
    with pytest.raises(ReplayInputError, match="can_tap: cannot be replayed"):
        build_nodes(["can_tap"], stack, ODD)


def test_the_recorded_reach_is_the_replayed_robots_without_building_the_world() -> None:
    """ADR 0066: the identification the actors were built from is in the recording;
    asked the same, the recorded robot answers it; asked otherwise, it identifies again;
    none recorded (a CAN robot, an older file), none."""
    world = MujocoInterface("empty", robot=builtin_robot("burger"))
    measured = world.reach(0.22, 1.2)
    kept = reach_from_metadata(world_metadata(world))
    assert kept == ((0.22, 1.2), measured)
    robot = RecordedRobot(ODD, lambda: world, kept)
    assert robot.reach(0.22, 1.2) == measured
    assert not robot.built
    assert robot.reach(0.2, 1.0) == world.reach(0.2, 1.0)
    assert robot.built
    assert RecordedRobot(ODD, lambda: pytest.fail("built")).reach(0.22, 1.2) is None
