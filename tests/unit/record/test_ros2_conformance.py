"""Recordings as rosbag2 writes them (issue 25), checked by an independent reader,
rosbags: every channel's ``offered_qos_profiles`` and type hash, the bag directory,
and the ``otonav_msgs`` interface package against the schemas in recordings."""

from __future__ import annotations

import inspect
import sys
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest
import yaml
from mcap.reader import make_reader
from rosbags.interfaces import (
    ConnectionExtRosbag2,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
)
from rosbags.rosbag2 import Reader
from rosbags.rosbag2.metadata import parse_qos
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

import otonav.msgs
from otonav.msgs import Clock, Message, NavState, TFMessage, Time
from otonav.record._bag import write_bag_directory
from otonav.record._qos_profile import offered_qos_yaml
from otonav.record._schemas import schema_for
from otonav.record._type_hash import rihs01
from otonav.record._writer import RecordingWriter
from otonav.runtime._qos import DEFAULT_QOS, LATCHED_QOS, SENSOR_DATA_QOS, QoS

pytestmark = pytest.mark.unit

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "scripts"))

from interface_package import PACKAGE, TYPES, msg_files  # noqa: E402

ALL_TYPES = sorted(
    (
        c
        for c in vars(otonav.msgs).values()
        if inspect.isclass(c) and issubclass(c, Message) and "/msg/" in getattr(c, "ros_type", "")
    ),
    key=lambda c: c.ros_type,
)
JAZZY = get_typestore(Stores.ROS2_JAZZY)


@pytest.mark.parametrize("kind", ALL_TYPES, ids=lambda c: c.ros_type)
def test_the_type_hash_is_rosbags_hash_of_the_recorded_definition(kind: type[Message]) -> None:
    name, text = schema_for(kind)
    store = get_typestore(Stores.EMPTY)
    store.register(get_types_from_msg(text, name))
    # our schema text, hashed by rosbags' implementation of REP 2011
    assert rihs01(kind) == store.hash_rihs01(name)
    if name in JAZZY.fielddefs:  # and a stock type hashes as ROS 2 Jazzy's own
        assert rihs01(kind) == JAZZY.hash_rihs01(name)


@pytest.mark.parametrize(
    ("qos", "reliability", "durability", "depth"),
    [
        (DEFAULT_QOS, QosReliability.RELIABLE, QosDurability.VOLATILE, 10),
        (SENSOR_DATA_QOS, QosReliability.BEST_EFFORT, QosDurability.VOLATILE, 5),
        (LATCHED_QOS, QosReliability.RELIABLE, QosDurability.TRANSIENT_LOCAL, 1),
    ],
)
def test_offered_qos_yaml_parses_in_rosbags(
    qos: QoS, reliability: QosReliability, durability: QosDurability, depth: int
) -> None:
    (parsed,) = parse_qos(offered_qos_yaml([qos]))
    assert parsed.history == QosHistory.KEEP_LAST
    assert parsed.depth == depth
    assert parsed.reliability == reliability
    assert parsed.durability == durability
    assert parsed.liveliness == QosLiveliness.AUTOMATIC
    assert (parsed.deadline.sec, parsed.deadline.nsec) == (9223372036, 854775807)


def _record(path: Path) -> None:
    writer = RecordingWriter(path)
    offered = {"/tf_static": [LATCHED_QOS], "/clock": [SENSOR_DATA_QOS, SENSOR_DATA_QOS]}
    writer.offered_qos = lambda topic: offered.get(topic, [])
    writer.write("/tf_static", TFMessage(), 0.0)
    for i in range(1, 6):
        writer.write("/clock", Clock(clock=Time.from_seconds(i / 10)), i / 10)
    writer.write("/nav/state", NavState(state="driving"), 0.5)
    writer.finish()


def test_every_channel_carries_offered_qos_profiles_and_the_type_hash(tmp_path: Path) -> None:
    _record(tmp_path / "r.mcap")
    with (tmp_path / "r.mcap").open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    channels = {c.topic: c for c in summary.channels.values()}
    assert set(channels) == {"/tf_static", "/clock", "/nav/state"}
    for channel in channels.values():
        assert parse_qos(channel.metadata["offered_qos_profiles"])
        schema = summary.schemas[channel.schema_id]
        kind = next(c for c in ALL_TYPES if c.ros_type == schema.name)
        assert channel.metadata["topic_type_hash"] == rihs01(kind)
    (latched,) = parse_qos(channels["/tf_static"].metadata["offered_qos_profiles"])
    assert latched.durability == QosDurability.TRANSIENT_LOCAL
    assert len(parse_qos(channels["/clock"].metadata["offered_qos_profiles"])) == 2
    # no publisher known: ROS 2's default profile
    (default,) = parse_qos(channels["/nav/state"].metadata["offered_qos_profiles"])
    assert (default.reliability, default.depth) == (QosReliability.RELIABLE, 10)


def test_rosbags_reads_the_bag_directory_message_by_message(tmp_path: Path) -> None:
    _record(tmp_path / "r.mcap")
    bag = write_bag_directory(tmp_path / "r.mcap", tmp_path / "bag")
    assert sorted(p.name for p in bag.iterdir()) == ["bag_0.mcap", "metadata.yaml"]
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert info["version"] == 9
    store = get_typestore(Stores.ROS2_JAZZY)
    store.register(get_types_from_msg(schema_for(NavState)[1], NavState.ros_type))
    with Reader(bag) as reader:
        assert reader.message_count == 7
        by_topic = {c.topic: c for c in reader.connections}
        ext = by_topic["/tf_static"].ext
        assert isinstance(ext, ConnectionExtRosbag2)
        assert ext.offered_qos_profiles[0].durability == QosDurability.TRANSIENT_LOCAL
        assert by_topic["/nav/state"].digest == rihs01(NavState)
        decoded: list[tuple[str, int, Any]] = [
            (c.topic, t, store.deserialize_cdr(raw, c.msgtype)) for c, t, raw in reader.messages()
        ]
    clocks = [m.clock.nanosec for topic, _t, m in decoded if topic == "/clock"]
    assert clocks == [100_000_000 * i for i in range(1, 6)]
    assert [m.state for topic, _t, m in decoded if topic == "/nav/state"] == ["driving"]


def test_a_bag_needs_a_finished_recording(tmp_path: Path) -> None:
    writer = RecordingWriter(tmp_path / "cut.mcap")
    writer.write("/clock", Clock(), 0.0)
    writer._file.flush()  # left unfinished: no summary
    try:
        with pytest.raises(ValueError, match="unfinished recording"):
            write_bag_directory(tmp_path / "cut.mcap", tmp_path / "bag")
    finally:
        writer.finish()


def test_the_interface_package_msg_files_are_the_recorded_schemas() -> None:
    folder = ROOT / PACKAGE
    files = msg_files()
    on_disk = {p.name: p.read_text(encoding="utf-8") for p in (folder / "msg").glob("*.msg")}
    assert on_disk == files, (
        "otonav_msgs/msg differs from the schemas otonav records; regenerate it with "
        "python scripts/interface_package.py otonav_msgs/msg"
    )
    cmake = (folder / "CMakeLists.txt").read_text()
    assert "rosidl_generate_interfaces" in cmake
    for name in files:
        assert f'"msg/{name}"' in cmake
    package = ET.parse(folder / "package.xml").getroot()
    assert package.get("format") == "3"
    assert package.findtext("name") == PACKAGE
    assert package.findtext("member_of_group") == "rosidl_interface_packages"
    assert {e.text for e in package.iter("buildtool_depend")} >= {"rosidl_default_generators"}
    # every otonav_msgs type the recordings use is in the package
    assert {t.ros_type for t in TYPES} == {
        c.ros_type for c in ALL_TYPES if c.ros_type.startswith(f"{PACKAGE}/")
    }


def test_sweep_bag_makes_a_bag_beside_every_kept_recording(tmp_path: Path) -> None:
    from otonav.cli._sweep import _write_bags

    _record(tmp_path / "runs" / "a" / "recording.mcap")
    records: list[dict[str, Any]] = [
        {"artifacts": "runs/a"},
        {"artifacts": None},
        {"artifacts": "runs/gone"},
    ]
    _write_bags(tmp_path, records)
    with Reader(tmp_path / "runs" / "a" / "bag") as reader:
        assert reader.message_count == 7
