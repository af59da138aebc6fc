"""One writer per ``--out`` (issue 27 item 1): two runs into one directory used to both
exit 0 and both name ``same/recording.mcap``, which held only the second one's data.
Now the second is refused (one line, exit 2) before it touches a file."""

from __future__ import annotations

import fcntl
import os
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from otonav.record._outlock import OutputBusyError, lock_output

pytestmark = pytest.mark.unit


@contextmanager
def held_elsewhere(path: Path) -> Iterator[None]:
    """The lock as another process holds it: a flock on a descriptor of its own."""
    fd = os.open(path, os.O_RDONLY if path.is_dir() else os.O_RDWR)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        yield
    finally:
        os.close(fd)


@pytest.fixture
def busy_out(tmp_path: Path) -> Iterator[Path]:
    """An --out directory another run is writing, with that run's recording in it."""
    out = tmp_path / "same"
    out.mkdir()
    (out / "recording.mcap").write_bytes(b"the first run's recording")
    with held_elsewhere(out):
        yield out
    assert (out / "recording.mcap").read_bytes() == b"the first run's recording"


def test_a_second_run_into_one_out_is_refused(
    cli_fails: Callable[..., str], busy_out: Path
) -> None:
    cli_fails(["run", "--out", str(busy_out), "--seed", "2"], str(busy_out), "another otonav")


def test_a_second_sweep_into_one_out_is_refused(
    cli_fails: Callable[..., str], busy_out: Path
) -> None:
    argv = ["sweep", "--scenario", "acceptance", "--seeds", "1", "--out", str(busy_out)]
    cli_fails(argv, str(busy_out), "choose another --out")


def test_a_second_replay_into_one_file_is_refused(
    cli_fails: Callable[..., str], tmp_path: Path
) -> None:
    target = tmp_path / "replayed.mcap"
    target.write_bytes(b"an earlier replay")
    with held_elsewhere(target):
        argv = ["replay", str(tmp_path / "in.mcap"), "--node", "nav", "--out", str(target)]
        cli_fails(argv, str(target), "another otonav")
    assert target.read_bytes() == b"an earlier replay"


def test_run_scenario_refuses_a_directory_another_thread_writes(tmp_path: Path) -> None:
    """The service's per-run directories and every embedding go through run_scenario."""
    from otonav.scenario import run_scenario

    out = tmp_path / "run"
    entered, release = threading.Event(), threading.Event()

    def other_run() -> None:
        with lock_output(out):
            entered.set()
            release.wait(30)

    thread = threading.Thread(target=other_run)
    thread.start()
    try:
        assert entered.wait(30)
        with pytest.raises(OutputBusyError, match="another otonav"):
            run_scenario(out_dir=out)
    finally:
        release.set()
        thread.join()
    assert list(out.iterdir()) == []


def test_the_lock_is_reentrant_in_a_thread_and_released_after(tmp_path: Path) -> None:
    out = tmp_path / "out"
    with lock_output(out), lock_output(out):
        pass
    with held_elsewhere(out):  # released: another process can take it
        pass


def test_a_file_lock_leaves_no_empty_file_behind(tmp_path: Path) -> None:
    target = tmp_path / "sub" / "replayed.mcap"
    with lock_output(target, is_file=True):
        assert target.exists()
    assert not target.exists()


@pytest.mark.parametrize("command", ["run", "sweep"])
def test_an_out_naming_a_file_says_so(
    cli_fails: Callable[..., str], tmp_path: Path, command: str
) -> None:
    """Issue 41 case 24: ``--out afile`` said "afile: File exists"."""
    afile = tmp_path / "afile"
    afile.write_text("mine")
    extra = ["--scenario", "acceptance", "--seeds", "1"] if command == "sweep" else []
    for out in (afile, afile / "sub"):
        cli_fails([command, *extra, "--out", str(out)], f"--out {out}: ", "a file, not a dir")
    assert afile.read_text() == "mine"


def test_a_replay_out_naming_a_directory_says_so(
    cli_fails: Callable[..., str], tmp_path: Path
) -> None:
    argv = ["replay", str(tmp_path / "in.mcap"), "--node", "nav", "--out", str(tmp_path)]
    cli_fails(argv, f"--out {tmp_path}: is a directory", "the MCAP file")
