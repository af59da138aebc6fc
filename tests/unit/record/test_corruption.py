"""A damaged chunk is reported, never hidden (issue 17, item 1): info, plot and salvage
verify every chunk's CRC; salvage copies only chunks that verify (it used to copy the
damaged ones and write fresh CRCs over them), and each command says what it skipped
and exits 1."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from otonav.cli import main
from otonav.msgs import Clock, Odometry, Point, Pose, PoseWithCovariance, Time
from otonav.record._reader import MAGIC, RecordingError, read_messages, summarize
from otonav.record._writer import RecordingWriter

pytestmark = pytest.mark.unit

N = 400
STEP = 0.01
CHUNK_OPCODE = 0x06


def _record(path: Path) -> None:
    writer = RecordingWriter(path, chunk_size=2048)
    for i in range(N):
        t = i * STEP
        writer.write("/clock", Clock(clock=Time.from_seconds(t)), t)
        pose = PoseWithCovariance(pose=Pose(position=Point(x=t, y=0.5 * t)))
        writer.write("/odom", Odometry(pose=pose), t)
    writer.finish()


def _chunks(data: bytes) -> list[int]:
    """Offsets of the chunk records."""
    offsets, pos = [], len(MAGIC)
    while pos < len(data) - len(MAGIC):
        opcode, length = data[pos], struct.unpack_from("<Q", data, pos + 1)[0]
        if opcode == CHUNK_OPCODE:
            offsets.append(pos)
        pos += 9 + length
    return offsets


def _damaged(tmp_path: Path, how: str) -> tuple[Path, tuple[float, float]]:
    """A finished recording whose third chunk is damaged; its message time range."""
    path = tmp_path / f"{how}.mcap"
    _record(path)
    data = bytearray(path.read_bytes())
    chunk = _chunks(bytes(data))[2]
    start, end = struct.unpack_from("<QQ", data, chunk + 9)
    if how == "crc":  # the records intact, their checksum not: a bit flip in the header
        data[chunk + 9 + 24] ^= 0x01  # uncompressed_crc
    else:  # a bit flip in the compressed records
        (name_len,) = struct.unpack_from("<I", data, chunk + 9 + 28)
        body = chunk + 9 + 28 + 4 + name_len + 8
        data[body + 40] ^= 0x10
    path.write_bytes(bytes(data))
    return path, (start / 1e9, end / 1e9)


@pytest.fixture(params=["crc", "data"])
def damaged(request: pytest.FixtureRequest, tmp_path: Path) -> tuple[Path, tuple[float, float]]:
    return _damaged(tmp_path, request.param)


def _clock_times(path: Path) -> list[float]:
    return [t for _topic, t, _m in read_messages(path, ["/clock"])]


def test_an_intact_recording_verifies(tmp_path: Path) -> None:
    path = tmp_path / "ok.mcap"
    _record(path)
    assert len(_chunks(path.read_bytes())) > 5
    assert summarize(path).damaged == ()
    assert len(_clock_times(path)) == N


def test_reading_a_damaged_recording_raises_naming_the_chunk(
    damaged: tuple[Path, tuple[float, float]],
) -> None:
    path, _span = damaged
    with pytest.raises(
        RecordingError, match=r"1 damaged chunk: chunk at byte \d+ .*: CRC mismatch"
    ):
        _clock_times(path)


def test_info_reports_the_damaged_chunk_and_exits_1(
    capsys: pytest.CaptureFixture[str], damaged: tuple[Path, tuple[float, float]]
) -> None:
    path, (start, end) = damaged
    assert main(["info", str(path)]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    (line,) = err.strip().splitlines()
    assert f"{path}: 1 damaged chunk" in line
    assert f"sim time {start:.3f} .. {end:.3f}" in line
    assert len(summarize(path).damaged) == 1


def test_salvage_skips_the_damaged_chunk_and_says_so(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    damaged: tuple[Path, tuple[float, float]],
) -> None:
    path, (start, end) = damaged
    fixed = tmp_path / "fixed.mcap"
    assert main(["salvage", str(path), str(fixed)]) == 1
    out = capsys.readouterr()
    assert "Traceback" not in out.err
    assert "skipped 1 damaged chunk" in out.err
    assert f"sim time {start:.3f} .. {end:.3f}" in out.err
    # The copy verifies and holds every message except the damaged chunk's.
    assert summarize(fixed).damaged == ()
    times = _clock_times(fixed)
    assert times, "the intact chunks were copied"
    assert not [t for t in times if start <= t <= end]
    assert {round(t / STEP) for t in times} == {i for i in range(N) if not start <= i * STEP <= end}


def test_plot_draws_the_intact_chunks_and_warns(
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    damaged: tuple[Path, tuple[float, float]],
) -> None:
    path, _span = damaged
    png = tmp_path / "plot.png"
    assert main(["plot", str(path), "--out", str(png)]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert "1 damaged chunk" in err
    assert png.stat().st_size > 0
