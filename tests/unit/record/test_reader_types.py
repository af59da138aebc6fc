"""``read_messages`` yields otonav's own message types (ADR 0086), and a topic of a type
otonav has no class for is one clear line when asked for, skipped with a warning when
every topic is read (as ``ros2 bag play`` skips a type it does not know)."""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar

import pytest
from mcap.writer import Writer

from otonav.cli import main
from otonav.msgs import Clock, Frame, Header, Message, Time
from otonav.record._reader import RecordingError, read_messages
from otonav.record._schemas import schema_for
from otonav.record._writer import RecordingWriter
from otonav.record.cdr import ENCAPSULATION, encode

pytestmark = pytest.mark.unit

FOREIGN = "/battery"


def _recording(path: Path) -> Path:
    """/clock (otonav's type), a CAN frame (an array of bytes) and /battery, a type
    otonav has no class for, written by plain mcap as a ROS 2 tool would."""
    frame = Frame(header=Header(stamp=Time(sec=1)), id=0x0C, dlc=3, data=(1, 2, 255, 0, 0, 0, 0, 0))
    with path.open("wb") as f:
        writer = Writer(f)
        writer.start(profile="ros2", library="test")
        channels = {}
        for topic, message in (("/clock", Clock(clock=Time(sec=1))), ("/can", frame)):
            name, text = schema_for(type(message))
            schema = writer.register_schema(name, "ros2msg", text.encode())
            channels[topic] = (writer.register_channel(topic, "cdr", schema), encode(message))
        schema = writer.register_schema("sensor_msgs/msg/BatteryState", "ros2msg", b"float32 v")
        battery = writer.register_channel(FOREIGN, "cdr", schema)
        for channel, data in channels.values():
            writer.add_message(channel, 10**9, data, 10**9)
        writer.add_message(battery, 10**9, ENCAPSULATION + b"\0\0\x80?", 10**9)
        writer.finish()  # type: ignore[no-untyped-call]
    return path


def test_messages_are_otonav_types(tmp_path: Path) -> None:
    path = _recording(tmp_path / "r.mcap")
    ((_, t, clock),) = read_messages(path, ["/clock"])
    assert type(clock) is Clock
    assert (t, clock) == (1.0, Clock(clock=Time(sec=1)))
    ((_, _, frame),) = read_messages(path, ["/can"])
    assert type(frame) is Frame
    assert frame.data == (1, 2, 255, 0, 0, 0, 0, 0)  # a uint8[8] as a tuple, not bytes


def test_a_named_topic_of_an_unknown_type_is_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _recording(tmp_path / "r.mcap")
    with pytest.raises(RecordingError, match=r"/battery holds sensor_msgs/msg/BatteryState"):
        list(read_messages(path, [FOREIGN]))
    assert main(["echo", FOREIGN, str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert "no message type for" in err[0]


def test_every_topic_skips_an_unknown_type_with_a_warning(tmp_path: Path) -> None:
    path = _recording(tmp_path / "r.mcap")
    with pytest.warns(UserWarning, match=r"skipping /battery"):
        topics = [topic for topic, _t, _m in read_messages(path)]
    assert sorted(topics) == ["/can", "/clock"]


class Charge(Message):
    """A user's own message type (not in otonav.msgs)."""

    ros_type: ClassVar[str] = "my_msgs/msg/Charge"
    volts: float = 0.0
    cells: tuple[int, ...] = ()


def test_a_users_own_message_type_reads_back_as_itself(tmp_path: Path) -> None:
    path = tmp_path / "user.mcap"
    with RecordingWriter(path) as writer:
        writer.write("/charge", Charge(volts=24.5, cells=(3, 4)), 0.5)
    ((topic, t, charge),) = read_messages(path)
    assert (topic, t, type(charge)) == ("/charge", 0.5, Charge)
    assert charge == Charge(volts=24.5, cells=(3, 4))
