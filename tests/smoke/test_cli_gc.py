"""Layer 2: ``otonav run`` is not paused by a full garbage collection while it runs.

A process's first run allocates enough (lazily imported modules, caches, the world) that
CPython's cyclic collector runs a full (generation 2) collection in the middle of it,
walking every object imported: 40-80 ms on this machine, more than one 50 ms navigation
period of a real-time run. The CLI, when it is the process, freezes what start-up made
(ADR 0063), so a collection inside the run only looks at the run's own objects. A host
calling ``otonav.cli.main`` keeps its collector as it was: objects it holds at that
moment must stay collectable once it lets them go.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.smoke

# argv: how otonav is entered ("script": the console script's entry point, as the
# `otonav` command and `python -m otonav` run it; "host": otonav.cli.main called from
# Python), out dir. Prints the full collections that start while run_scenario runs, and
# how many objects are frozen after it.
CHILD = """
import gc, sys, time
import otonav.scenario

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
argv = ["run", "--scenario", "acceptance", "--out", sys.argv[2]]
if sys.argv[1] == "script":
    from otonav._entry import main as script
    sys.argv = ["otonav", *argv]
    code = script()
else:
    from otonav.cli import main
    code = main(argv)
print("FULL", " ".join(f"{ms:.1f}" for ms in full), flush=True)
print("FROZEN", gc.get_freeze_count(), flush=True)
sys.exit(code)
"""


def _run(how: str, out: Path) -> dict[str, list[str]]:
    done = subprocess.run(
        [sys.executable, "-c", CHILD, how, str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    words = [line.split() for line in done.stdout.splitlines()]
    return {w[0]: w[1:] for w in words if w and w[0] in ("FULL", "FROZEN")}


def test_a_cli_run_has_no_full_collection_of_start_up_objects(tmp_path: Path) -> None:
    printed = _run("script", tmp_path / "out")
    assert printed["FULL"] == [], f"full collections inside the run, ms: {printed['FULL']}"


def test_a_host_calling_the_cli_keeps_its_collector_as_it_was(tmp_path: Path) -> None:
    printed = _run("host", tmp_path / "out")
    assert printed["FROZEN"] == ["0"], printed
