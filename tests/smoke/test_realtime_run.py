"""Layer 2: a scenario run paced to the wall clock reaches the goal, paced (not racing)."""

from __future__ import annotations

import threading
from pathlib import Path

import pytest

from otonav.record._outlock import OutputBusyError, lock_output
from otonav.runtime import RealTime
from otonav.scenario import run_scenario
from otonav.scenario._builtin import BUILTIN

pytestmark = pytest.mark.smoke

SCALE = 10.0  # the "empty" scenario takes ~8.5 s of sim time: ~0.85 s of wall time


def test_realtime_run_reaches_the_goal_paced_to_the_scaled_wall_clock(tmp_path: Path) -> None:
    # One entry point for a judged run: real time is a mode of run_scenario (ADR 0055).
    verdict = run_scenario(BUILTIN["empty"], out_dir=tmp_path, time=RealTime(SCALE))

    assert verdict.passed, verdict.reason
    assert verdict.reached
    assert verdict.final_distance_m <= BUILTIN["empty"].goal_tolerance
    ratio = verdict.sim_time_s / verdict.wall_time_s
    # Paced, not racing: never faster than the scale. (The lower bound only says sim time
    # followed the wall at all; the stack alone runs at ~60x, far above 0.2 * SCALE.)
    assert 0.2 * SCALE <= ratio <= 1.2 * SCALE, (
        f"sim {verdict.sim_time_s:.3f} s in wall {verdict.wall_time_s:.3f} s: "
        f"ratio {ratio:.2f}, expected about the scale {SCALE:g}"
    )
    assert verdict.recording is not None
    assert Path(verdict.recording).stat().st_size > 0
    assert verdict.plot is not None
    assert Path(verdict.plot).is_file()


@pytest.mark.parametrize("scale", [0.0, 1e308, 1e-9])
def test_realtime_run_rejects_a_scale_it_cannot_honour(scale: float) -> None:
    with pytest.raises(ValueError, match=r"scale.*must be a number in \[0.01, 100\]"):
        run_scenario(BUILTIN["empty"], time=RealTime(scale), record=False, plot=False)


def test_a_realtime_run_refuses_an_out_dir_another_run_writes_to(tmp_path: Path) -> None:
    """The same ending and guards as a virtual-time run: one run per out_dir."""
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
            run_scenario(BUILTIN["empty"], out_dir=out, time=RealTime(SCALE))
    finally:
        release.set()
        thread.join()
    assert list(out.iterdir()) == []


def test_hold_without_the_viewer_is_refused() -> None:
    with pytest.raises(ValueError, match="hold= needs gui=True"):
        run_scenario(BUILTIN["empty"], record=False, plot=False, hold=print)
