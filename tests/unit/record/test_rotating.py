"""A long-lived recording stays under its cap: finished files rotate out, each one an
indexed recording that starts with the same metadata, none lost in between."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from otonav.msgs import Clock, Time
from otonav.record._reader import read_messages, summarize
from otonav.record._rotating import RotatingRecordingWriter

pytestmark = pytest.mark.unit

CHUNK = 1024


def _write(path: Path, count: int, *, max_bytes: int, keep: int) -> RotatingRecordingWriter:
    writer = RotatingRecordingWriter(path, max_bytes=max_bytes, keep=keep, chunk_size=CHUNK)
    writer.add_metadata("otonav.world", {"obstacles": "[]", "walls": "[]"})
    for i in range(count):
        writer.write("/clock", Clock(clock=Time.from_seconds(i / 100)), i / 100)
    writer.finish()
    return writer


def _times(path: Path) -> list[float]:
    return [t for _topic, t, _m in read_messages(path, ["/clock"])]


def test_rotation_keeps_the_newest_files_under_the_cap(tmp_path: Path) -> None:
    live = tmp_path / "live.mcap"
    writer = _write(live, 20_000, max_bytes=8 * CHUNK, keep=2)
    assert writer.rotations >= 3
    files = sorted(p.name for p in tmp_path.iterdir())
    assert files == ["live.1.mcap", "live.2.mcap", "live.mcap"]
    for path in (writer.rotated(2), writer.rotated(1), live):
        summary = summarize(path)
        assert not summary.truncated
        assert summary.metadata == {
            "otonav.recording": {"format_version": "2"},
            "otonav.world": {"obstacles": "[]", "walls": "[]"},
        }
        assert path.stat().st_size < 8 * CHUNK + 2 * CHUNK + 4096  # one chunk + summary over
    # Oldest to newest, the kept files are contiguous: no message lost at a rotation.
    times = _times(writer.rotated(2)) + _times(writer.rotated(1)) + _times(live)
    assert times[-1] == pytest.approx(199.99)
    steps = {round(b - a, 6) for a, b in itertools.pairwise(times)}
    assert steps == {0.01}


def test_keep_zero_keeps_only_the_current_file(tmp_path: Path) -> None:
    live = tmp_path / "live.mcap"
    writer = _write(live, 5_000, max_bytes=4 * CHUNK, keep=0)
    assert writer.rotations >= 1
    assert [p.name for p in tmp_path.iterdir()] == ["live.mcap"]
    assert _times(live)[-1] == pytest.approx(49.99)


def test_a_cap_below_one_chunk_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="at least one chunk"):
        RotatingRecordingWriter(tmp_path / "x.mcap", max_bytes=100, chunk_size=CHUNK)
