"""``run --gui --foxglove``: MuJoCo's viewer draws the run in a real window (under Xvfb,
as tests/smoke/test_gui.py does) while a real WebSocket client gets the same run's
topics live, byte for byte what the recording holds."""

from __future__ import annotations

import subprocess
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from foxglove_client import FoxgloveClient
from test_foxglove_live import _free_port
from test_gui import CLI_GUI_CHILD, _Child, _robot, _screen_of, _screenshot, _start_children

from otonav.replay._recording import load_recording
from otonav.runtime._clock import MAX_STEP_BATCH

pytestmark = pytest.mark.smoke


@pytest.fixture
def cli_gui_child(tmp_path: Path) -> Iterator[Callable[..., _Child]]:
    yield from _start_children(tmp_path, CLI_GUI_CHILD)


def test_gui_and_foxglove_together(cli_gui_child: Callable[..., _Child], tmp_path: Path) -> None:
    port = _free_port()
    # empty scenario: ~9 s of sim time to the goal, ~2 s of wall time at scale 5. Sim time
    # holds at the start until the client below has subscribed (--foxglove-wait). --hold
    # keeps the window (and its X server) up after the run: on a loaded machine the viewer
    # may first draw the robot after the last step, and a screenshot taken as the child
    # exits loses its display (CI, stop 34: xwd exit 1).
    child = cli_gui_child(
        "run", "--gui", "--hold", "--scenario", "empty", "--scale", "5", "--out", tmp_path,
        "--foxglove", "--foxglove-port", port, "--foxglove-wait", "30",
    )  # fmt: skip
    display, xauthority = _screen_of(child)
    expect = {"/odom", "/clock", "/tf", "/scan"}
    # The CLI announces the server once it listens (the server binds before the line).
    child.expect_stderr("foxglove: serving", timeout=30)
    client = FoxgloveClient(f"ws://127.0.0.1:{port}", expect=expect, subscribe={"/odom", "/clock"})
    client.start()
    deadline = time.monotonic() + 30.0
    # The window is up and draws the robot while the client is served (or, at the latest,
    # once the run is held).
    seen = (0, 0.0, 0.0)
    while seen[0] < 30 and time.monotonic() < deadline and child.proc.poll() is None:
        try:
            seen = _robot(_screenshot(display, xauthority))
        except subprocess.CalledProcessError as exc:
            child.proc.wait(timeout=10)  # the X server went: the child ended
            raise AssertionError(f"no screenshot ({exc.stderr!r}){child}") from None
    assert seen[0] >= 30, f"no robot on screen: {seen}{child}"
    child.expect("the recording is finished;", timeout=60)  # the run ended, window held
    child.send("close")
    assert child.expect("EXIT", timeout=15) == ["0"], str(child)
    client.stop()
    assert child.proc.wait(timeout=10) == 0, str(child)

    assert client.subprotocol == "foxglove.websocket.v1"
    odom = load_recording(tmp_path / "recording.mcap", ["/odom"]).messages
    recorded = [(m.time_ns, m.data) for m in odom]
    got = client.received["/odom"]
    assert len(recorded) > 800  # ~9 s at 100 Hz
    # What arrived is the recorded run itself: the same CDR bytes, in order, none lost
    # on the way (a client that keeps up).
    assert [data for _t, data in got] == [data for _t, data in recorded]
    # Stamped with the sim time of its publication, as the recorder stamps it, or later
    # by at most one step of the real-time clock: the recorder's tap and the live view's
    # each read the clock, and in real time reading it follows the wall clock, stepping
    # the world by up to MAX_STEP_BATCH (50 ms) when the host was held up in between.
    lags = {t_got - t_rec for (t_got, _), (t_rec, _) in zip(got, recorded, strict=True)}
    assert min(lags) == 0, lags
    assert max(lags) <= round(MAX_STEP_BATCH * 1e9), lags
    stamps = [t for t, _ in client.received["/clock"]]
    assert stamps == sorted(stamps)
    assert stamps[-1] >= recorded[-1][0] - 20_000_000
