"""Real ROS 2 nodes against ``otonav run --ros2`` (issue 37): Jazzy's and Kilted's rclpy
on Fast DDS, from PyPI, each in its own venv (``make ros2-peers``), in processes of their
own. Every test runs against both distros. The nodes import no otonav (tests/ros2/).

Nothing here waits on a wall-clock duration: a peer says ``ready`` once it exists, the
bridge holds sim time until it matched (``--ros2-wait``/lockstep), and each process ends
on its own; the ``timeout`` of ``communicate`` only catches a hang.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import pytest
from dds_domain import exclusive_domain

from otonav.record._reader import read_messages, summarize

pytestmark = pytest.mark.sil

ROOT = Path(__file__).resolve().parents[2]
NODES = ROOT / "tests" / "ros2"
DISTROS = ["jazzy", "kilted"]
HANG = 120.0
"""Wall seconds: a hang, never a timing assertion."""


def _python(distro: str) -> Path:
    python = ROOT / ".venvs" / f"ros2-{distro}" / "bin" / "python"
    assert python.exists(), f"{python} is missing: `make ros2-peers` installs it (make test does)"
    return python


def _env(domain: int) -> dict[str, str]:
    """This environment without any DDS, ROS or library-path setting of its own (the ROS
    wheels' bootstrap sets LD_LIBRARY_PATH for their own venv), on ``domain``, localhost."""
    dropped = ("ROS_", "RMW_", "CYCLONEDDS", "_ROS_WHEELS", "AMENT_")
    env = {
        key: value
        for key, value in os.environ.items()
        if not key.startswith(dropped) and key not in ("LD_LIBRARY_PATH", "PYTHONPATH")
    }
    env |= {"ROS_DOMAIN_ID": str(domain), "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    return env


@contextmanager
def _process(argv: list[str], env: dict[str, str]) -> Iterator[subprocess.Popen[str]]:
    proc = subprocess.Popen(
        argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT
    )
    try:
        yield proc
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.communicate()


@contextmanager
def _qos_peer(distro: str, env: dict[str, str]) -> Iterator[subprocess.Popen[str]]:
    """tests/ros2/qos_peer.py in ``distro``'s venv, once it said ``ready`` (its
    subscriptions exist); it reports once its ROS time passed 2 s."""
    with _process([str(_python(distro)), str(NODES / "qos_peer.py"), "2.0"], env) as peer:
        assert peer.stdout is not None
        assert peer.stdout.readline().strip() == "ready"
        yield peer


def _otonav(*args: str) -> list[str]:
    return [sys.executable, "-m", "otonav", "run", "--ros2", *args]


@pytest.mark.timeout(180)
@pytest.mark.parametrize("distro", DISTROS)
def test_a_plain_rclpy_node_receives_odom_scan_imu_and_clock_and_sees_the_actors_as_nodes(
    tmp_path: Path, distro: str
) -> None:
    """/odom subscribed ``(…, 10)`` (reliable, as diff_drive_controller offers it), /scan
    and /imu with the sensor-data profile, /clock through use_sim_time: every one
    arrives, and rclpy reports no incompatible QoS. The run is paced (plain --ros2).
    ``get_node_names_and_namespaces()`` lists otonav's actors, with their topics."""
    scenario = tmp_path / "short.yaml"
    scenario.write_text("name: short\nscene: empty\ngoal: {x: 3.0, y: 0.0}\nsim_budget: 3.0\n")
    with exclusive_domain() as domain:
        env = _env(domain)
        with _qos_peer(distro, env) as peer:
            run = _otonav(
                "--ros2-wait", "60", "--scale", "4", "--scenario", str(scenario),
                "--no-record", "--out", str(tmp_path / "out"),
            )  # fmt: skip
            with _process(run, env) as otonav:
                out, err = peer.communicate(timeout=HANG)
                otonav.communicate(timeout=HANG)
    assert peer.returncode == 0, err
    report = json.loads(out.strip().splitlines()[-1])
    assert report["problems"] == []
    assert report["ros_time"] >= 2.0  # its clock followed /clock
    counts = report["counts"]
    # 2 s of sim time: /odom and /imu at 50 Hz, /scan at 10 Hz (best effort may lose a few)
    assert counts["/odom"] >= 90, counts
    assert counts["/imu"] >= 80, counts
    assert counts["/scan"] >= 15, counts
    # the node graph (ros_discovery_info): otonav's actors as nodes, each with what it
    # publishes, as `ros2 node list` / `ros2 node info` show them
    nodes = report["nodes"]
    assert {"/bridge", "/nav", "/safety", "/base", "/ros2"} <= nodes.keys(), nodes
    assert {"/odom", "/scan", "/imu", "/clock", "/tf"} <= set(nodes["/bridge"])
    assert "/cmd_vel_nav" in nodes["/nav"]
    assert "/cmd_vel" in nodes["/safety"]


@pytest.mark.timeout(180)
@pytest.mark.parametrize("distro", DISTROS)
def test_a_go_to_goal_node_publishing_twist_stamped_passes_in_lockstep(
    tmp_path: Path, distro: str
) -> None:
    """The same node publishing TwistStamped (Jazzy's diff_drive_controller default) with
    ``ros2.twist_stamped``: otonav takes it in as the Twist its safety layer reads. Each
    answer is taken in at its 0.05 s instant of sim time."""
    out = tmp_path / "out"
    with exclusive_domain() as domain:
        env = _env(domain)
        run = _otonav(
            "--ros2-in", "/cmd_vel_nav", "--lockstep", "/cmd_vel_nav:0.05",
            "--set", "nav.planner=external", "--set", "ros2.twist_stamped=true",
            "--out", str(out),
        )  # fmt: skip
        with _process(run, env) as otonav:
            node_argv = [
                str(_python(distro)), str(NODES / "go_to_goal.py"),
                "--ros-args", "-p", "use_sim_time:=true", "-p", "stamped:=true",
            ]  # fmt: skip
            with _process(node_argv, env):
                _stdout, err = otonav.communicate(timeout=HANG)
    assert otonav.returncode == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["passed"], summary
    assert summary["time_to_goal_s"] < 20.0
    recording = out / "recording.mcap"
    assert not summarize(recording).truncated
    answers = [t for _topic, t, _m in read_messages(recording, ["/cmd_vel_nav"])]
    # one answer per 0.05 s instant, each taken in at that instant of sim time
    assert len(answers) >= summary["time_to_goal_s"] / 0.05
    assert all(abs(t / 0.05 - round(t / 0.05)) < 1e-6 for t in answers), answers[:5]
    assert answers[:3] == pytest.approx([0.05, 0.10, 0.15])


@pytest.mark.timeout(180)
@pytest.mark.parametrize("distro", DISTROS)
def test_otonav_play_drives_a_use_sim_time_nodes_clock(tmp_path: Path, distro: str) -> None:
    """``otonav play`` writes a recording onto DDS at its pace, /clock included (ros2 bag
    play --clock): the node's ROS time follows the recording, and /odom arrives with
    the QoS it was recorded with (reliable: the node's default subscription matches)."""
    scenario = tmp_path / "short.yaml"
    scenario.write_text("name: short\nscene: empty\ngoal: {x: 3.0, y: 0.0}\nsim_budget: 3.0\n")
    out = tmp_path / "out"
    recorded = subprocess.run(
        [sys.executable, "-m", "otonav", "run", "--scenario", str(scenario), "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=HANG,
    )
    assert (out / "recording.mcap").exists(), recorded.stderr
    with exclusive_domain() as domain:
        env = _env(domain)
        with _qos_peer(distro, env) as peer:
            player = [
                sys.executable, "-m", "otonav", "play", str(out / "recording.mcap"),
                "--wait", "60", "--rate", "4",
            ]  # fmt: skip
            with _process(player, env) as playing:
                report_line, err = peer.communicate(timeout=HANG)
                _out, play_err = playing.communicate(timeout=HANG)
    assert playing.returncode == 0, play_err
    assert peer.returncode == 0, err
    report = json.loads(report_line.strip().splitlines()[-1])
    assert report["ros_time"] >= 2.0
    assert report["problems"] == []
    assert report["counts"]["/odom"] >= 90, report["counts"]


@pytest.mark.timeout(180)
@pytest.mark.parametrize("distro", DISTROS)
def test_an_async_parameter_client_sets_the_navigators_top_speed_mid_run(
    tmp_path: Path, distro: str
) -> None:
    """otonav run where rclpy is importable (the distro's venv) serves each actor's
    parameters as ROS 2 parameter services: rclpy's AsyncParameterClient lists them, sets
    /nav's ``params.dwa.max_v`` to 0.15 m/s at 3 s of sim time, and the recorded commands
    and /odom obey it from then on; a refused value, a wrong type, a parameter that does
    not exist and a read-only one are each an unsuccessful result with the reason."""
    out = tmp_path / "out"
    python = str(_python(distro))
    with exclusive_domain() as domain:
        env = _env(domain)
        run = [python, "-m", "otonav", "run", "--ros2", "--ros2-wait", "60", "--scale", "2"]
        with _process([*run, "--out", str(out)], env) as otonav:
            peer_argv = [python, str(NODES / "param_peer.py"), "nav", "params.dwa.max_v"]
            with _process([*peer_argv, "0.15", "3.0"], env) as peer:
                report_line, peer_err = peer.communicate(timeout=HANG)
            _stdout, run_err = otonav.communicate(timeout=HANG)
    assert peer.returncode == 0, peer_err
    assert otonav.returncode in (0, 1), run_err  # the slower robot may miss its budget
    assert "Traceback" not in run_err
    report = json.loads(report_line.strip().splitlines()[-1])
    assert "params.dwa.max_v" in report["names"], report
    assert report["set"] == {"successful": True, "reason": ""}
    assert report["value"] == 0.15
    assert not report["negative"]["successful"]
    assert "the bound of base.max_v" in report["negative"]["reason"]
    assert not report["string"]["successful"]
    assert not report["missing"]["successful"]
    assert not report["read_only"]["successful"]
    assert "read-only" in report["read_only"]["reason"]
    set_at = report["set_at"]
    recording = out / "recording.mcap"
    # the change is recorded on /parameter_events, at the instant it took effect
    ((stamp, event),) = [(t, m) for _topic, t, m in read_messages(recording, ["/parameter_events"])]
    assert event.node == "/nav"
    ((changed,),) = [event.changed_parameters]
    assert (changed.name, changed.value.double_value) == ("params.dwa.max_v", 0.15)
    assert 3.0 <= stamp <= set_at + 0.5  # the peer reads /clock, 100 Hz, a beat behind
    commands = [(t, m.linear.x) for _topic, t, m in read_messages(recording, ["/cmd_vel_nav"])]
    assert max(v for t, v in commands if t < set_at - 0.5) > 0.3  # it was faster before
    assert max(v for t, v in commands if t > set_at + 0.2) <= 0.15 + 1e-9
    odom = sorted(
        m.twist.twist.linear.x
        for _topic, t, m in read_messages(recording, ["/odom"])
        if t > set_at + 1.0
    )
    assert odom[int(0.95 * len(odom))] <= 0.16, odom[-10:]  # the odometry's own jitter aside


@pytest.mark.sim(wall_ceiling=150)
@pytest.mark.parametrize("distro", DISTROS)
async def test_a_pytest_scenario_runs_a_ros2_node_in_its_sim_time(
    tmp_path: Path, distro: str
) -> None:
    """The same through the pytest plugin: ``running_stack`` with a ``ros2`` section that
    asks for lockstep; the test's ``until`` waits on sim time while the rclpy node
    drives the robot to the goal."""
    import math

    from otonav.msgs import Point, Pose, PoseStamped
    from otonav.runtime import LATCHED_QOS, until
    from otonav.stack import StackConfig
    from otonav.testing import running_stack

    with exclusive_domain() as domain:
        env = _env(domain)
        config = StackConfig.model_validate(
            {
                "nav": {"planner": "external"},
                "ros2": {
                    "enabled": True,
                    "domain_id": domain,
                    "inputs": ("/cmd_vel_nav",),
                    "lockstep": ({"topic": "/cmd_vel_nav", "period": 0.05},),
                    "wait": 60.0,
                },
            }
        )
        node_argv = [
            str(_python(distro)), str(NODES / "go_to_goal.py"),
            "--ros-args", "-p", "use_sim_time:=true",
        ]  # fmt: skip
        with _process(node_argv, env):
            async with running_stack(config) as stack:
                goal = stack.system.publisher("/goal", PoseStamped, LATCHED_QOS, name="test")
                await goal.publish(PoseStamped(pose=Pose(position=Point(x=1.2, y=0.6))))

                def distance() -> float:
                    truth = stack.hal.ground_truth()
                    return math.hypot(1.2 - truth.x, 0.6 - truth.y)

                # the node stops within 0.06 m by its odometry
                await until(lambda: distance() < 0.12, within=15.0, observe=distance)
                assert stack.ros2 is not None


def _lockstep_run(out: Path, python: Path, env: dict[str, str]) -> dict[str, Any]:
    run = _otonav(
        "--ros2-in", "/cmd_vel_nav", "--lockstep", "/cmd_vel_nav:0.05",
        "--set", "nav.planner=external", "--out", str(out),
    )  # fmt: skip
    with _process(run, env) as otonav:
        node_argv = [str(python), str(NODES / "go_to_goal.py"), "--ros-args"]
        with _process([*node_argv, "-p", "use_sim_time:=true"], env):
            _stdout, err = otonav.communicate(timeout=HANG)
    assert otonav.returncode == 0, err
    summary: dict[str, Any] = json.loads((out / "summary.json").read_text())
    return summary


@pytest.mark.timeout(240)
@pytest.mark.parametrize("distro", DISTROS)
def test_an_unmodified_rclpy_go_to_goal_node_passes_in_lockstep_and_again_the_same_way(
    tmp_path: Path, distro: str
) -> None:
    """use_sim_time, a 20 Hz timer, /odom + /scan in, /cmd_vel_nav out: otonav holds sim
    time at each 0.05 s until the node answered, and the run is judged on ground truth
    (the node publishes no NavState); started before the node, as a user would. A
    second run with the same node has the same verdict and time to goal (within 0.1 s).
    (The recordings are byte-identical on a quiet machine, not always under load: ADR
    0065; benchmarks/ros2_lockstep_bench.py counts them.)"""
    with exclusive_domain() as domain:
        env = _env(domain)
        first = _lockstep_run(tmp_path / "first", _python(distro), env)
        second = _lockstep_run(tmp_path / "second", _python(distro), env)
    for summary in (first, second):
        assert summary["passed"], summary
        assert summary["time_to_goal_s"] < 20.0
    assert abs(first["time_to_goal_s"] - second["time_to_goal_s"]) <= 0.1
