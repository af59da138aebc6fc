"""Layer 2: ``otonav run`` is not paused by a full garbage collection while it runs.

A process's first run allocates enough (lazily imported modules, caches, the world) that
CPython's cyclic collector runs a full (generation 2) collection in the middle of it,
walking every object imported: 40-80 ms on this machine, more than one 50 ms navigation
period of a real-time run. The CLI freezes what start-up made (ADR 0063), so a
collection inside the run only looks at the run's own objects.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.smoke

# argv: out dir. Counts the full collections that start while run_scenario runs.
CHILD = """
import gc, sys, time
import otonav.scenario
from otonav.cli import main

inside = [False]
full = []
started = [0.0]

def watch(phase, info):
    if not inside[0] or info["generation"] != 2:
        return
    if phase == "start":
        started[0] = time.perf_counter()
    else:
        full.append((time.perf_counter() - started[0]) * 1e3)

run_scenario = otonav.scenario.run_scenario

def run_watched(*args, **kwargs):
    inside[0] = True
    try:
        return run_scenario(*args, **kwargs)
    finally:
        inside[0] = False

otonav.scenario.run_scenario = run_watched
gc.callbacks.append(watch)
code = main(["run", "--scenario", "acceptance", "--out", sys.argv[1]])
print("FULL", " ".join(f"{ms:.1f}" for ms in full), flush=True)
sys.exit(code)
"""


def test_a_cli_run_has_no_full_collection_of_start_up_objects(tmp_path: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-c", CHILD, str(tmp_path / "out")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    (line,) = [ln for ln in done.stdout.splitlines() if ln.startswith("FULL")]
    pauses = line.split()[1:]
    assert pauses == [], f"full collections inside the run, ms: {pauses}"
