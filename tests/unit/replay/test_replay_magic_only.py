"""``replay`` on a file that is the MCAP magic and (almost) nothing else printed only
"Invalid argument" (issue 27 item 9): mcap's reader seeks to a footer before the file's
start. Now one line names the file and says what it is, and whether salvage applies."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.cli import main
from otonav.msgs import Clock, Time
from otonav.record._reader import MAGIC
from otonav.record._writer import RecordingWriter

pytestmark = pytest.mark.unit


def _error_line(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    assert main(argv) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    return lines[0]


@pytest.mark.parametrize("extra", [b"", b"\x01\x02\x03"])
def test_replay_of_the_magic_alone_names_the_file_and_what_it_is(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: bytes
) -> None:
    path = tmp_path / "magic.mcap"
    path.write_bytes(MAGIC + extra)
    line = _error_line(["replay", str(path), "--node", "nav"], capsys)
    assert line == (
        f"otonav: error: {path}: not a complete MCAP recording: {len(MAGIC) + len(extra)} "
        "bytes, the MCAP magic and no readable header after it (an empty or cut-off file; "
        "nothing to salvage)"
    )
    line = _error_line(["salvage", str(path), str(tmp_path / "fixed.mcap")], capsys)
    assert line.startswith(f"otonav: error: {path}: no readable MCAP header after the magic (")
    assert "nothing to salvage" in line
    assert not (tmp_path / "fixed.mcap").exists()


def test_replay_of_a_header_too_short_for_a_footer_points_to_salvage(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    whole = tmp_path / "whole.mcap"
    with RecordingWriter(whole) as writer:
        writer.write("/clock", Clock(clock=Time.from_seconds(0.0)), 0.0)
    header_end = 8 + 1 + 8 + int.from_bytes(whole.read_bytes()[9:17], "little")
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(whole.read_bytes()[: header_end + 5])  # shorter than a footer
    line = _error_line(["replay", str(cut), "--node", "nav"], capsys)
    assert line.startswith(f"otonav: error: {cut}: the recording is cut off")
    assert f"'otonav salvage {cut} RECOVERED.mcap'" in line
