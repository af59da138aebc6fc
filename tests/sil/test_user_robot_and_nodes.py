"""Your robot and your nodes through every surface: ``otonav run``, ``sweep``,
``replay`` and ``running_stack``, with a robot and a node from outside ``otonav/``;
the built-in ``burger`` on the acceptance course and the seven built-in courses."""

from __future__ import annotations

import json
import logging
import shlex
from pathlib import Path

import pytest
from mcap.reader import make_reader

from otonav.cli import main
from otonav.msgs import Log, NavState
from otonav.record._reader import read_messages
from otonav.runtime import until
from otonav.scenario import ScenarioConfig, run_scenario
from otonav.scenario._builtin import BUILTIN
from otonav.stack import StackConfig
from otonav.stack._config import RobotConfig
from otonav.testing import running_stack

pytestmark = pytest.mark.sil

ROOT = Path(__file__).resolve().parents[2]
PATHFINDER = ROOT / "examples" / "my_robot"
MY_NODES = ROOT / "examples" / "my_nodes"
COURSES = ("empty", "box", "slalom", "gap", "u_trap", "corridor", "cluttered")


def metadata(path: Path, name: str) -> dict[str, str]:
    with path.open("rb") as f:
        for record in make_reader(f).iter_metadata():
            if record.name == name:
                return dict(record.metadata)
    raise AssertionError(f"no {name} metadata in {path}")


@pytest.mark.parametrize("config", ["stack.yaml", "stack_urdf.yaml"])
def test_a_users_robot_runs_the_acceptance_course(config: str, tmp_path: Path) -> None:
    assert main(["run", "--config", str(PATHFINDER / config), "--out", str(tmp_path)]) == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["passed"]
    assert summary["min_clearance_m"] >= 0.3
    world = metadata(tmp_path / "recording.mcap", "otonav.world")
    robot = json.loads(world["robot"])
    assert robot["wheel_radius"] == pytest.approx(0.0762, abs=1e-4)
    assert robot["wheel_separation"] == pytest.approx(0.30)
    sources = json.loads(world["robot_sources"])
    assert "mesh geom" in sources["wheel_radius"]
    assert summary["robot"]["wheel_radius"] == robot["wheel_radius"]


def test_a_users_node_through_run_and_replay(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    config = MY_NODES / "stack.yaml"
    assert (
        main(["run", "--scenario", "empty", "--config", str(config), "--out", str(tmp_path)]) == 0
    )
    recording = tmp_path / "recording.mcap"
    states = [m.state for _t, _s, m in read_messages(recording, ["/nav/state"])]
    assert states[-1] == "reached"  # published by the user's node
    watch = [m for _t, _s, m in read_messages(recording, ["/rosout"]) if m.level == Log.WARN]
    assert not [m for m in watch if m.name == "command_watch"]  # it was fed: no warning
    capsys.readouterr()
    assert main(["replay", str(recording), "--node", "planner"]) == 0
    assert "SAME: every output byte-identical" in capsys.readouterr().out
    # changed parameters change what the node does: the replay diverges
    assert (
        main(["replay", str(recording), "--node", "planner", "--set", "actors.planner.max_v=0.2"])
        == 1
    )


def test_a_users_node_in_a_sweep_with_its_parameter_varied(tmp_path: Path) -> None:
    args = [
        "sweep", "--scenario", "empty", "--out", str(tmp_path),
        "--actor", f"{MY_NODES / 'simple_planner.py'}:StraightToGoal",
        "--set", "nav.planner=external", "--set", "actors.straight_to_goal.max_v=0.2,0.3",
    ]  # fmt: skip
    assert main(args) == 0
    records = [json.loads(line) for line in (tmp_path / "results.jsonl").read_text().splitlines()]
    assert sorted(r["overrides"]["actors.straight_to_goal.max_v"] for r in records) == [0.2, 0.3]
    assert all(r["status"] == "passed" for r in records)
    slow, fast = sorted(records, key=lambda r: r["overrides"]["actors.straight_to_goal.max_v"])
    assert slow["time_to_goal_s"] > fast["time_to_goal_s"]  # the parameter reached the node
    # the repro line launches the node too, so it reruns the run alone
    assert f"--actor {MY_NODES / 'simple_planner.py'}:StraightToGoal" in slow["repro"]
    repro = shlex.split(slow["repro"])[2:]
    assert main(["run", *repro, "--out", str(tmp_path / "repro"), "--no-record"]) == 0
    again = json.loads((tmp_path / "repro" / "summary.json").read_text())
    assert again["time_to_goal_s"] == slow["time_to_goal_s"]


@pytest.mark.sim(wall_ceiling=60)
async def test_running_stack_brings_up_a_users_robot_and_node_from_one_file(
    tmp_path: Path,
) -> None:
    config = tmp_path / "stack.yaml"
    config.write_text(
        f"robot:\n  model: {PATHFINDER / 'pathfinder.xml'}\n  base: chassis_link\n"
        "  left_wheel: left_wheel_hinge\n  right_wheel: right_wheel_hinge\n"
        "nav: {planner: external}\n"
        "actors:\n"
        f"  - {{name: planner, class: '{MY_NODES / 'simple_planner.py'}:StraightToGoal'}}\n"
    )
    async with running_stack(config) as stack:
        from otonav.msgs import Header, Point, Pose, PoseStamped, Time
        from otonav.runtime import LATCHED_QOS

        assert stack.hal.geometry.wheel_radius == pytest.approx(0.0762, abs=1e-4)
        goal = stack.system.publisher("/goal", PoseStamped, LATCHED_QOS, name="test")
        await goal.publish(
            PoseStamped(header=Header(stamp=Time()), pose=Pose(position=Point(x=1.0, y=0.5)))
        )
        states = stack.system.subscribe("/nav/state", NavState)
        last = ["none"]

        def arrived() -> bool:
            while (message := states.try_recv()) is not None:
                last[0] = message.state
            return last[0] == "reached"

        await until(arrived, within=15.0, observe=lambda: last[0])
        truth = stack.hal.ground_truth()
        assert (truth.x - 1.0) ** 2 + (truth.y - 0.5) ** 2 < 0.15**2


@pytest.mark.parametrize("course", ["acceptance", *COURSES])
def test_burger_passes_the_courses_within_budgets_scaled_to_its_speed(course: str) -> None:
    stack = StackConfig(robot=RobotConfig(model="burger"))
    scenario = BUILTIN[course]
    verdict = run_scenario(scenario, stack, record=False, plot=False)
    assert verdict.passed, verdict.reason
    assert verdict.sim_budget_s == pytest.approx(scenario.sim_budget * 0.4 / 0.22, abs=1e-3)
    assert verdict.robot["max_v"] == 0.22


def test_an_external_planner_nobody_feeds_is_named_within_a_second(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    stack = StackConfig.model_validate({"nav": {"planner": "external"}})
    scenario = ScenarioConfig.model_validate(
        {"scene": "empty", "goal": {"x": 2.0, "y": 0.0}, "sim_budget": 2.0}
    )
    with caplog.at_level(logging.WARNING, logger="otonav"):
        verdict = run_scenario(scenario, stack, out_dir=tmp_path, plot=False)
    assert not verdict.passed
    warnings = [
        (stamp, m.msg)
        for _t, stamp, m in read_messages(tmp_path / "recording.mcap", ["/rosout"])
        if m.name == "command_watch" and m.level == Log.WARN
    ]
    assert len(warnings) == 1
    stamp, text = warnings[0]
    assert stamp <= 1.0 + 1e-6
    assert "/cmd_vel_nav" in text
    assert "nav.planner is 'external'" in text
    assert any("no message on /cmd_vel_nav" in r.getMessage() for r in caplog.records)


@pytest.mark.parametrize(
    ("args", "line"),
    [
        (["--set", "robot.model=nope.xml"], "robot.model: 'nope.xml' is neither a built-in robot"),
        (
            ["--config", str(PATHFINDER / "stack.yaml"), "--set", "robot.left_wheel=wheel_l"],
            "robot.left_wheel: no joint 'wheel_l' in ",
        ),
        (
            ["--config", str(MY_NODES / "stack.yaml"), "--set", "actors.planner.max_v=-1"],
            "actors.planner.max_v: Input should be greater than 0 (got -1)",
        ),
        (["--actor", "no_such_pkg_q:Node"], "actors.node.class: cannot import 'no_such_pkg_q'"),
    ],
)
def test_bad_robot_or_node_input_is_one_line_and_exit_2(
    args: list[str], line: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "keep.txt").write_text("recorded before")
    assert main(["run", "--out", str(tmp_path), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"otonav: error: {line}")
    assert "\n" not in err
    assert (tmp_path / "keep.txt").read_text() == "recorded before"


def test_an_external_planner_that_publishes_no_nav_state_is_judged_on_ground_truth(
    tmp_path: Path,
) -> None:
    """A ROS 2 planner cannot publish otonav_msgs/NavState (issue 37): with nav.planner
    external, arriving (within the tolerance, stopped 2 s later) is the pass. The example
    planner's /nav/state is remapped away, so nobody tells the judge 'reached'."""
    config = tmp_path / "stack.yaml"
    config.write_text(
        "nav: {planner: external}\n"
        "actors:\n"
        f"  - name: planner\n    class: '{MY_NODES / 'simple_planner.py'}:StraightToGoal'\n"
        "    remap: {/nav/state: /planner/state}\n"
    )
    out = tmp_path / "out"
    args = ["run", "--scenario", "empty", "--config", str(config), "--out", str(out)]
    assert main(args) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["passed"], summary
    assert summary["time_to_goal_s"] is not None
    assert not list(read_messages(out / "recording.mcap", ["/nav/state"]))
    assert list(read_messages(out / "recording.mcap", ["/planner/state"]))


def test_the_robots_frame_names_are_what_its_config_says(tmp_path: Path) -> None:
    """robot.frames (issue 37 item 5): a Nav2-style robot's base_footprint and its
    laser's link name stamp /odom, /tf, /tf_static, /scan and /imu; odom stays odom."""
    out = tmp_path / "out"
    args = [
        "run", "--scenario", "empty", "--set", "robot.frames.base=base_footprint",
        "--set", "robot.frames.laser=base_scan", "--set", "robot.frames.imu=imu",
        "--out", str(out),
    ]  # fmt: skip
    assert main(args) == 0
    recording = out / "recording.mcap"
    ((_topic, _t, odom),) = read_messages(recording, ["/odom"], end=0.015)
    assert (odom.header.frame_id, odom.child_frame_id) == ("odom", "base_footprint")
    ((_topic, _t, tf),) = read_messages(recording, ["/tf"], end=0.015)
    assert [(t.header.frame_id, t.child_frame_id) for t in tf.transforms] == [
        ("odom", "base_footprint")
    ]
    ((_topic, _t, static),) = read_messages(recording, ["/tf_static"])
    assert {(t.header.frame_id, t.child_frame_id) for t in static.transforms} == {
        ("base_footprint", "base_scan"),
        ("base_footprint", "imu"),
    }
    (scan, imu) = (next(read_messages(recording, [t]))[2] for t in ("/scan", "/imu"))
    assert (scan.header.frame_id, imu.header.frame_id) == ("base_scan", "imu")
