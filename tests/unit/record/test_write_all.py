"""RecordingWriter.write_all (the recorder's drain) writes the same file as one write()
per message."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.msgs import Clock, Header, Log, Message, Time
from otonav.record.writer import RecordingWriter

pytestmark = pytest.mark.unit


def _deliveries() -> list[tuple[str, float, Message]]:
    out: list[tuple[str, float, Message]] = []
    for n in range(3000):  # several 4 KiB chunks, channels appearing as they come
        t = n * 0.01
        stamp = Time.from_seconds(t)
        out.append(("/clock", t, Clock(clock=stamp)))
        if n % 3 == 0:
            out.append(
                ("/rosout", t, Log(stamp=stamp, level=Log.INFO, name="x", msg="y" * (n % 9)))
            )
        if n % 5 == 0:
            out.append((f"/h{n % 2}", t, Header(stamp=stamp, frame_id="f" * (n % 7))))
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
