"""A full disk (issue 27 item 5), injected where the bytes go: the file object raises
``OSError(ENOSPC)`` once a byte budget is used up, as a full file system does.

The recording writer raises one :class:`DiskFullError` naming the file, keeps what
reached the disk readable, and drops what comes after; the recorder stops the run
instead of crashing; ``salvage`` onto a full disk removes its partial output. The same
with the kernel's own refusal (``RLIMIT_FSIZE``) through the CLI:
``tests/smoke/test_disk_full_cli.py``."""

from __future__ import annotations

import errno
import io
from pathlib import Path
from typing import Any

import pytest

from otonav.msgs import Clock, Time
from otonav.record._diskfull import DiskFullError, is_disk_full
from otonav.record._reader import read_messages, summarize
from otonav.record._salvage import salvage
from otonav.record._writer import RecordingWriter

pytestmark = pytest.mark.unit


class _FullAfter(io.RawIOBase):
    """A raw file that takes ``budget`` bytes, then raises ENOSPC (partial writes
    first, as write(2) does when the last block fills)."""

    def __init__(self, raw: Any, budget: int) -> None:
        self._raw = raw
        self.budget = budget

    def writable(self) -> bool:
        return True

    def seekable(self) -> bool:
        return True

    def tell(self) -> int:
        return int(self._raw.tell())

    def seek(self, offset: int, whence: int = 0) -> int:
        return int(self._raw.seek(offset, whence))

    def write(self, b: Any) -> int:
        data = bytes(b)
        if self.budget <= 0:
            raise OSError(errno.ENOSPC, "No space left on device", self._raw.name)
        n = min(len(data), self.budget)
        self._raw.write(data[:n])
        self.budget -= n
        return n

    def close(self) -> None:
        self._raw.close()
        super().close()


def _full_disk(monkeypatch: pytest.MonkeyPatch, budget: int) -> list[_FullAfter]:
    """The recording writer's files (``open(path, "wb")``) go to a disk that fills after
    ``budget`` bytes; other opens are left alone. Returns the files made."""
    import builtins

    import otonav.record._writer as writer_module

    made: list[_FullAfter] = []

    def full_open(file: Any, mode: str = "r", *args: Any, **kwargs: Any) -> Any:
        if mode == "wb":
            raw = _FullAfter(builtins.open(file, "wb", buffering=0), budget)  # noqa: SIM115
            made.append(raw)
            return io.BufferedWriter(raw)
        return builtins.open(file, mode, *args, **kwargs)

    monkeypatch.setattr(writer_module, "open", full_open, raising=False)
    return made


def test_a_full_disk_is_one_error_naming_the_file_and_the_recording_stays_readable(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "r.mcap"
    _full_disk(monkeypatch, 20_000)
    writer = RecordingWriter(path, chunk_size=1024)
    failures = []
    failed_at = -1
    for i in range(2000):
        try:
            writer.write("/clock", Clock(clock=Time.from_seconds(i / 100)), i / 100)
        except DiskFullError as exc:
            failures.append(exc)
            failed_at = i
    assert len(failures) == 1  # once; then dropped, counted
    error = failures[0]
    assert error.path == path
    assert str(error).startswith(f"{path}: no space left on device; the recording was ")
    assert is_disk_full(error.cause)
    assert 100 < failed_at < 1000
    assert writer.dropped == 2000 - failed_at - 1
    writer.finish()  # already closed: no second error
    # What reached the disk is a readable MCAP: every message of the chunks on disk.
    times = [t for _topic, t, _m in read_messages(path, ["/clock"])]
    assert len(times) > 100
    assert times == [i / 100 for i in range(len(times))]
    assert summarize(path).message_count == len(times)


def test_a_disk_full_while_finishing_raises_once_and_keeps_the_chunks(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "r.mcap"
    made = _full_disk(monkeypatch, 1 << 30)
    writer = RecordingWriter(path, chunk_size=1024)
    for i in range(300):
        writer.write("/clock", Clock(clock=Time.from_seconds(i / 100)), i / 100)
    made[0].budget = 0  # the disk fills: the footer and index do not fit
    with pytest.raises(DiskFullError, match="no space left on device"):
        writer.finish()
    writer.finish()
    monkeypatch.undo()
    assert len(list(read_messages(path, ["/clock"]))) > 200


def test_salvage_onto_a_full_disk_removes_its_partial_output_and_names_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    source = tmp_path / "src.mcap"
    with RecordingWriter(source, chunk_size=1024) as writer:
        for i in range(3000):
            writer.write("/clock", Clock(clock=Time.from_seconds(i / 100)), i / 100)
    target = tmp_path / "out" / "fixed.mcap"
    target.parent.mkdir()
    real_open = Path.open

    def full_open(self: Path, mode: str = "r", *args: Any, **kwargs: Any) -> Any:
        if self == target and "w" in mode:
            return io.BufferedWriter(_FullAfter(real_open(self, "wb"), 10_000))
        return real_open(self, mode, *args, **kwargs)

    monkeypatch.setattr(Path, "open", full_open)
    with pytest.raises(DiskFullError) as caught:
        salvage(source, target)
    assert caught.value.path == target
    assert str(caught.value).startswith(f"{target}: no space left on device; ")
    assert "partial copy was removed" in str(caught.value)
    assert not target.exists()
    monkeypatch.undo()
    # And a retry (with room) is not refused for a leftover target.
    assert salvage(source, target) == 3000
