"""ROS 2's names and QoS on DDS, as rmw_cyclonedds_cpp makes them (ADR 0047)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from otonav.actors import topics
from otonav.msgs import Clock, Odometry, PoseStamped
from otonav.record._type_hash import rihs01
from otonav.ros2._naming import (
    LOCALHOST_CONFIG,
    LOCKSTEP_CONFIG,
    NETWORK_CONFIG,
    Ros2Error,
    dds_qos,
    dds_topic,
    dds_type_name,
    discovery,
    domain_id,
)

pytestmark = pytest.mark.unit


def test_topic_and_type_names_are_ros2s() -> None:
    assert dds_topic("/odom") == "rt/odom"
    assert dds_topic("/nav/state") == "rt/nav/state"
    assert dds_type_name(Odometry) == "nav_msgs::msg::dds_::Odometry_"
    assert dds_type_name(Clock) == "rosgraph_msgs::msg::dds_::Clock_"
    with pytest.raises(Ros2Error, match="not a ROS 2 topic name"):
        dds_topic("odom")


def test_qos_maps_reliability_depth_durability_and_the_type_hash() -> None:
    odom = dds_qos(topics.SENSOR_QOS, Odometry)
    assert (odom.reliable, odom.depth, odom.transient_local) == (False, 5, False)
    goal = dds_qos(topics.LATCHED, PoseStamped)
    assert (goal.reliable, goal.depth, goal.transient_local) == (True, 1, True)
    assert goal.user_data == f"typehash={rihs01(PoseStamped)};".encode()


def test_domain_id_from_the_flag_or_ros_domain_id() -> None:
    assert domain_id(None, {}) == 0
    assert domain_id(None, {"ROS_DOMAIN_ID": "42"}) == 42
    assert domain_id(7, {"ROS_DOMAIN_ID": "42"}) == 7
    with pytest.raises(Ros2Error, match=r"^--ros2-domain 233: must be 0\.\.232"):
        domain_id(233, {})
    with pytest.raises(Ros2Error, match=r"^ROS_DOMAIN_ID='x'"):
        domain_id(None, {"ROS_DOMAIN_ID": "x"})


def test_discovery_stays_on_this_host_unless_asked() -> None:
    assert discovery({}).config == LOCALHOST_CONFIG
    assert discovery({"ROS_LOCALHOST_ONLY": "1"}).localhost
    assert discovery({"ROS_AUTOMATIC_DISCOVERY_RANGE": "localhost"}).localhost
    wide = discovery({"ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET"})
    assert (wide.config, wide.localhost) == (NETWORK_CONFIG, False)
    assert "network" in wide.scope
    with pytest.raises(Ros2Error, match="OFF"):
        discovery({"ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF"})
    with pytest.raises(Ros2Error, match="must be LOCALHOST"):
        discovery({"ROS_AUTOMATIC_DISCOVERY_RANGE": "MARS"})


def test_the_users_cyclonedds_uri_applies_after_ours() -> None:
    """Cyclone reads no CYCLONEDDS_URI once given a configuration: it is appended, as
    rmw_cyclonedds does, so the user's file still overrides."""
    uri = "file:///etc/my-cyclone.xml"
    assert discovery({"CYCLONEDDS_URI": uri}).config == f"{LOCALHOST_CONFIG},{uri}"
    network = {"ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET", "CYCLONEDDS_URI": uri}
    assert discovery(network).config == f"{NETWORK_CONFIG},{uri}"
    # lockstep's faster heartbeat comes after ours and before the user's
    lockstep = discovery({"CYCLONEDDS_URI": uri}, lockstep=True).config
    assert lockstep == f"{LOCALHOST_CONFIG},{LOCKSTEP_CONFIG},{uri}"


def test_cyclonedds_is_imported_only_when_a_bridge_is_made() -> None:
    code = (
        "import sys, otonav.ros2, otonav.cli._run, otonav.ros2._naming; "
        "print('cyclonedds' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize(
    ("argv", "line"),
    [
        (["--ros2", "--ros2-domain", "300"], "--ros2-domain 300: must be 0..232"),
        (["--ros2-domain", "3"], "--ros2-domain: only with --ros2"),
        (["--ros2", "--ros2-in", "odom"], "--ros2-in 'odom': not a ROS 2 topic name"),
        (["--set", "ros2.domain_id=999"], "ros2.domain_id"),
    ],
)
def test_bad_ros2_input_is_one_line_and_exit_2(
    argv: list[str], line: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from otonav.cli import main

    code = main(["run", *argv, "--out", str(tmp_path)])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1, err
    assert line in err
