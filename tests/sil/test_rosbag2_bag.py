"""``otonav run --bag`` and ``otonav replay --out --bag`` write rosbag2 bag directories
that rosbags, an independent reader, opens as a bag: every message decodes, and each
topic's QoS is the one its publishers offered in the stack (issue 25)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from rosbags.interfaces import ConnectionExtRosbag2, QosDurability, QosReliability
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from otonav.cli import main
from otonav.record._reader import summarize

pytestmark = pytest.mark.sil


def _read_all(bag: Path) -> dict[str, tuple[list[object], ConnectionExtRosbag2]]:
    """topic -> (every message decoded, its rosbag2 connection data)."""
    store = get_typestore(Stores.ROS2_JAZZY)
    out: dict[str, tuple[list[object], ConnectionExtRosbag2]] = {}
    with Reader(bag) as reader:
        for c in reader.connections:
            if c.msgtype not in store.fielddefs:  # otonav_msgs: from the bag's own schema
                store.register(get_types_from_msg(c.msgdef.data, c.msgtype))
            assert isinstance(c.ext, ConnectionExtRosbag2)
            out[c.topic] = ([], c.ext)
        for c, _t, raw in reader.messages():
            out[c.topic][0].append(store.deserialize_cdr(raw, c.msgtype))
    return out


def test_run_bag_is_a_rosbag2_directory_rosbags_reads_with_every_qos(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    assert main(["run", "--out", str(tmp_path), "--bag"]) == 0
    assert f"bag: {tmp_path / 'bag'}" in capsys.readouterr().out
    recorded = {t.topic: t.count for t in summarize(tmp_path / "recording.mcap").topics}
    topics = _read_all(tmp_path / "bag")
    assert {t: len(m) for t, (m, _e) in topics.items()} == recorded
    for topic, (_messages, ext) in topics.items():
        assert ext.offered_qos_profiles, topic
        for qos in ext.offered_qos_profiles:
            assert qos.reliability != QosReliability.UNKNOWN, topic
            assert qos.durability != QosDurability.UNKNOWN, topic
    # latched topics are offered transient-local, so `ros2 bag play` latches them again
    for latched in ("/tf_static", "/goal"):
        (qos,) = topics[latched][1].offered_qos_profiles
        assert qos.durability == QosDurability.TRANSIENT_LOCAL
    assert topics["/scan"][1].offered_qos_profiles[0].reliability == QosReliability.BEST_EFFORT
    (verdict,) = topics["/scenario/verdict"][0]
    assert verdict.passed  # type: ignore[attr-defined]

    # replay's output, as a bag too
    written = tmp_path / "replayed.mcap"
    argv = ["replay", str(tmp_path / "recording.mcap"), "--node", "nav", "--out", str(written)]
    assert main([*argv, "--bag"]) == 0
    replayed = _read_all(tmp_path / "replayed_bag")
    assert len(replayed["/cmd_vel_nav"][0]) == recorded["/cmd_vel_nav"]
    assert len(replayed["/recorded/cmd_vel_nav"][0]) == recorded["/cmd_vel_nav"]
    (qos,) = replayed["/tf_static"][1].offered_qos_profiles
    assert qos.durability == QosDurability.TRANSIENT_LOCAL


def test_bag_needs_a_recording(cli_fails: Callable[..., str], tmp_path: Path) -> None:
    cli_fails(["run", "--out", str(tmp_path), "--bag", "--no-record"], "--bag", "--no-record")
    cli_fails(["replay", str(tmp_path / "r.mcap"), "--node", "nav", "--bag"], "--bag", "--out")
