"""RecordingWriter.write_all (the recorder's drain) writes the same file as one write()
per message."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.actors._bridge import CLOCK, ODOM
from otonav.hal.can._bus import RawFrame
from otonav.hal.can._tap import frames_of
from otonav.msgs import Clock, Header, Log, Message, Time
from otonav.record._writer import RecordingWriter

pytestmark = pytest.mark.unit


def _deliveries() -> list[tuple[str, float, Message]]:
    out: list[tuple[str, float, Message]] = []
    for n in range(3000):  # several 4 KiB chunks, channels appearing as they come
        t = 1.0 + n * 0.01
        stamp = Time.from_seconds(t)
        out.append(("/clock", t, Clock(clock=stamp)))
        if n % 3 == 0:
            out.append(
                ("/rosout", t, Log(stamp=stamp, level=Log.INFO, name="x", msg="y" * (n % 9)))
            )
        if n % 5 == 0:
            out.append((f"/h{n % 2}", t, Header(stamp=stamp, frame_id="f" * (n % 7))))
        if n % 4 == 1:  # fixed-layout messages, packed rather than encoded field by field
            out.append(("/flat_clock", t, CLOCK(stamp.sec, stamp.nanosec)))
            out.append(("/odom", t, ODOM(stamp.sec, stamp.nanosec, t, -t, 0.0, 1.0, 0.5, n)))
        if n % 7 == 0:  # a batch (the CAN tap's flush): a run of one topic and instant
            raw = [(t - 0.01 * k, RawFrame(0x29 + k, bytes(k), k == 3, False)) for k in range(5)]
            out.extend(("/can/frames", t, frame) for frame in frames_of("can0", raw))
        if n % 11 == 0:  # a topic name equal to an earlier one, not the same object
            out.append(("".join(["/clo", "ck"]), t, Clock(clock=stamp)))
        if n % 97 == 1:  # a publisher that waited for room: stamped earlier
            out.append(("/late", t - 0.5, Clock(clock=Time.from_seconds(t - 0.5))))
    return out


def _file(path: Path, batched: bool) -> bytes:
    with RecordingWriter(path, chunk_size=4096) as writer:
        deliveries = _deliveries()
        if batched:
            writer.write_all(iter(deliveries[:100]))
            writer.write_all(iter(deliveries[100:]))
        else:
            for topic, t, message in deliveries:
                writer.write(topic, message, t)
        assert writer.messages == len(deliveries)
    return path.read_bytes()


def test_write_all_writes_the_same_bytes_as_write(tmp_path: Path) -> None:
    assert _file(tmp_path / "a.mcap", True) == _file(tmp_path / "b.mcap", False)


def test_a_subclass_that_overrides_write_sees_every_message(tmp_path: Path) -> None:
    seen: list[str] = []

    class Spy(RecordingWriter):
        def write(self, topic: str, message: Message, sim_time: float) -> bool:
            seen.append(topic)
            return super().write(topic, message, sim_time)

    with Spy(tmp_path / "s.mcap") as writer:
        writer.write_all(iter(_deliveries()[:50]))
    assert seen == [topic for topic, _, _ in _deliveries()[:50]]


def test_what_was_encoded_before_a_bad_message_is_written(tmp_path: Path) -> None:
    good = _deliveries()[:40]
    bad = ("/clock", 1.0, Clock.model_construct(clock=Time.model_construct(sec=2**40)))
    with RecordingWriter(tmp_path / "a.mcap") as writer:
        with pytest.raises(ValueError, match="cannot encode"):
            writer.write_all(iter([*good, bad]))
        assert writer.messages == len(good)
    with RecordingWriter(tmp_path / "b.mcap") as writer:
        for topic, t, message in good:
            writer.write(topic, message, t)
        writer._sequence[writer._channels["/clock"]] += 1  # the bad one took its number
    assert (tmp_path / "a.mcap").read_bytes() == (tmp_path / "b.mcap").read_bytes()
