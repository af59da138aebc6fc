"""The wall-clock ceiling ends a run whatever its actors do (issue 41, case 20): with a
user's actor publishing in a tight loop (sim time never moves on), the 300 s ceiling
fired but the process was still alive at 341 s, and a 20 s ceiling through the API
returned after 48 s. The loop checked its ceiling every 256 passes, and each pass
drained a flood into the recording.

The bound asserted is the issue's own (the run is over within 5 s of its ceiling): a
hang bound, not a speed target (the run does nothing but wait for its ceiling)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.smoke

HERE = Path(__file__).resolve().parent
CEILING_S = 3.0
WITHIN_S = 5.0
RUN = """
import sys, time
sys.path.insert(0, {here!r})
from pathlib import Path
from ending_actors import Floods
from otonav.runtime import WallClockCeilingError
from otonav.scenario import ScenarioConfig, run_scenario
start = time.monotonic()
try:
    run_scenario(ScenarioConfig(scene="empty"), out_dir=Path({out!r}), plot=False,
                 wall_ceiling={ceiling}, extra_actors=(Floods(),))
except WallClockCeilingError as exc:
    print("ceiling", time.monotonic() - start, str(exc).splitlines()[0])
"""


@pytest.mark.timeout(120)
def test_a_flooding_actor_does_not_hold_the_ceiling_off(tmp_path: Path) -> None:
    code = RUN.format(here=str(HERE), out=str(tmp_path / "out"), ceiling=CEILING_S)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=100)
    assert done.returncode == 0, done.stderr[-3000:]
    word, wall, message = done.stdout.strip().split(" ", 2)
    assert word == "ceiling", done.stdout
    assert f"wall-clock ceiling of {CEILING_S:g} s" in message
    print(f"\nended {float(wall) - CEILING_S:.2f} s after its {CEILING_S:g} s ceiling")
    assert float(wall) <= CEILING_S + WITHIN_S, f"ended {wall} s after its start"
