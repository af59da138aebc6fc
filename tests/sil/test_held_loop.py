"""An actor that computes without yielding holds the loop (issue 27 item 3): it ran
698 s past an 8 s ceiling and SIGTERM was ignored. A watchdog thread now enforces the
ceiling and the stop request from outside the loop, names the actor, and the recording
is still finished. (The ceilings here are wall-clock by nature: they only catch hangs;
nothing is asserted on wall time.)"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from children import terminal_signals

from otonav.record._reader import summarize
from otonav.runtime import Actor, WallClockCeilingError

pytestmark = pytest.mark.sil

CHILD = Path(__file__).with_name("hog_child.py")


class Hog(Actor):
    async def run(self) -> None:
        await self.clock.sleep_until(0.5)
        spins = 0
        while True:  # never yields
            spins += 1


@pytest.mark.timeout(60)
def test_the_ceiling_fires_on_a_held_loop_and_names_the_actor(tmp_path: Path) -> None:
    from otonav.scenario import run_scenario

    with pytest.raises(WallClockCeilingError) as caught:
        run_scenario(out_dir=tmp_path, wall_ceiling=2.0, plot=False, extra_actors=(Hog("hog"),))
    message = str(caught.value)
    assert "wall-clock ceiling of 2 s" in message
    assert "actor 'hog'" in message
    assert "test_held_loop.py" in message  # where it was computing
    assert not summarize(tmp_path / "recording.mcap").truncated


@pytest.mark.timeout(60)
@pytest.mark.parametrize(("sig", "code"), [("TERM", 143), ("INT", 130)])
def test_a_signal_stops_a_held_loop_and_names_the_actor(
    tmp_path: Path, sig: str, code: int
) -> None:
    done = subprocess.run(
        [sys.executable, str(CHILD), str(tmp_path), sig],
        capture_output=True,
        text=True,
        timeout=50,
        preexec_fn=terminal_signals,
    )
    assert done.returncode == code, done.stderr
    assert "Traceback (most recent call last)" not in done.stderr
    # the actor's crash (one line, then the user's own frame where it held the loop:
    # issue 39), how the run ended
    lines = [
        line
        for line in done.stderr.strip().splitlines()
        if not line.startswith((" ", "Traceback (your code")) and "HeldError" not in line
    ]
    assert len(lines) <= 2, done.stderr
    assert "actor 'hog' (at hog_child.py" in lines[-1], done.stderr
    assert not summarize(tmp_path / "recording.mcap").truncated
    assert not (tmp_path / "summary.json").exists()
