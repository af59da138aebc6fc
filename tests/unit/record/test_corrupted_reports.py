"""``info`` and ``plot`` on corrupted recordings (issue 41, cases 18 and 23): one line
on stderr, never a traceback, and "cut off" only for a file that was cut off.

A bit flip in a schema of the summary section gave ``plot`` a UnicodeDecodeError
traceback (mcap_ros2's ``decoder_for``); full-length files with a flip in the index or in
a record outside the chunks were said to be "cut off (no index) ... 0 messages"."""

from __future__ import annotations

import random
import struct
from collections.abc import Iterator
from pathlib import Path

import pytest

from otonav.cli import main
from otonav.msgs import Clock, Odometry, Point, Pose, PoseWithCovariance, Time
from otonav.record._reader import MAGIC, summarize
from otonav.record._writer import RecordingWriter

pytestmark = pytest.mark.unit

N = 300
STEP = 0.01
SCHEMA, CHUNK, METADATA, DATA_END = 0x03, 0x06, 0x0C, 0x0F


def _record(path: Path) -> None:
    writer = RecordingWriter(path, chunk_size=2048)
    writer.add_metadata("otonav", {"scenario": "corrupted", "note": "x" * 200})
    for i in range(N):
        t = i * STEP
        writer.write("/clock", Clock(clock=Time.from_seconds(t)), t)
        pose = PoseWithCovariance(pose=Pose(position=Point(x=t, y=0.5 * t)))
        writer.write("/odom", Odometry(pose=pose), t)
    writer.finish()


def _records(data: bytes) -> Iterator[tuple[int, int, int]]:
    """(offset, opcode, length) of every top-level record."""
    pos = len(MAGIC)
    while pos < len(data) - len(MAGIC):
        opcode, length = data[pos], struct.unpack_from("<Q", data, pos + 1)[0]
        yield pos, opcode, length
        pos += 9 + length


def _flipped(tmp_path: Path, name: str, where: str) -> Path:
    """A full-length recording with one record's content broken (its length intact):
    ``schema``: the text of every schema in the summary section (not valid UTF-8 now);
    ``metadata``: the metadata record written before the first chunk."""
    path = tmp_path / f"{name}.mcap"
    _record(path)
    data = bytearray(path.read_bytes())
    records = list(_records(bytes(data)))
    data_end = next(offset for offset, opcode, _ in records if opcode == DATA_END)
    if where == "schema":  # every schema of the index
        broken = [r for r in records if r[1] == SCHEMA and r[0] > data_end]
    else:
        broken = [next(r for r in records if r[1] == METADATA)]
    for offset, _opcode, length in broken:
        data[offset + 9 + length - 10] = 0xFF  # never valid in UTF-8: the text does not decode
    path.write_bytes(bytes(data))
    assert path.stat().st_size == len(data)
    return path


def _stderr_lines(capsys: pytest.CaptureFixture[str]) -> list[str]:
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return [line for line in err.splitlines() if line.strip()]


@pytest.mark.parametrize("where", ["schema", "metadata"])
def test_a_flip_outside_the_chunks_is_one_line_and_not_cut_off(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, where: str
) -> None:
    path = _flipped(tmp_path, where, where)
    for argv in (["info", str(path)], ["plot", str(path), "--out", str(tmp_path / "p.png")]):
        code = main(argv)
        lines = [line for line in _stderr_lines(capsys) if "UserWarning" not in line]
        assert code in (1, 2), (argv, lines)
        assert len(lines) == 1, (argv, lines)
        assert lines[0].startswith("otonav: "), lines
        assert str(path) in lines[0]
        assert "cut off" not in lines[0], lines[0]
    if where == "metadata":  # the chunks are intact: every message is still counted
        assert summarize(path).message_count == 2 * N
    else:  # replay refuses a damaged index, and does not call it cut off either
        assert main(["replay", str(path), "--node", "nav"]) == 2
        (line,) = _stderr_lines(capsys)
        assert "damaged: the index (summary section) fails its CRC" in line, line


def test_a_cut_off_file_is_said_to_be_cut_off(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "cut.mcap"
    _record(path)
    data = path.read_bytes()
    path.write_bytes(data[: len(data) * 2 // 3])
    assert main(["info", str(path)]) == 0
    (line,) = _stderr_lines(capsys)
    assert "was cut off (no index)" in line


def test_a_cut_off_file_with_a_damaged_chunk_is_one_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "cut_and_damaged.mcap"
    _record(path)
    data = bytearray(path.read_bytes())
    offset, _op, _length = [r for r in _records(bytes(data)) if r[1] == CHUNK][1]
    data[offset + 9 + 24] ^= 0x01  # its uncompressed CRC
    path.write_bytes(bytes(data[: len(data) * 2 // 3]))
    for argv in (["info", str(path)], ["plot", str(path), "--out", str(tmp_path / "p.png")]):
        assert main(argv) == 1
        (line,) = [line for line in _stderr_lines(capsys) if line.startswith("otonav: ")]
        assert "was cut off (no index) and 1 damaged chunk: chunk at byte" in line, line


def test_random_flips_in_full_length_files_are_never_called_cut_off(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    clean = tmp_path / "clean.mcap"
    _record(clean)
    data = clean.read_bytes()
    for seed in range(30):
        rng = random.Random(seed)
        flipped = bytearray(data)
        for _ in range(rng.choice([1, 4, 32])):
            i = rng.randrange(len(MAGIC), len(flipped) - len(MAGIC))
            flipped[i] ^= 1 << rng.randrange(8)
        path = tmp_path / f"flip{seed}.mcap"
        path.write_bytes(bytes(flipped))
        for argv in (["info", str(path)], ["plot", str(path), "--out", str(tmp_path)]):
            code = main(argv)
            lines = [line for line in _stderr_lines(capsys) if line.startswith("otonav: ")]
            assert len(lines) <= 1, (seed, argv, lines)
            assert not any("cut off" in line for line in lines), (seed, argv, lines)
            assert code in (0, 1, 2), (seed, argv, code)
