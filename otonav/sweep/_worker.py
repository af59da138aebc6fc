"""What a worker does with one :class:`RunTask`, whatever the backend: run the scenario
through the public :func:`~otonav.scenario.run_scenario` in a private scratch
directory, hash the recording, and hand back the verdict figures plus, for runs the
sweep keeps, the artifacts as bytes. The driver alone writes into ``--out``, so a
worker on another machine needs no shared filesystem
(docs/adr/0018-sweep-backends-and-artifacts.md).

A worker imports otonav once and runs many tasks; nothing of one run survives into the
next (each run builds its own world, loop and recorder), which is what makes a run's
recording the same in any worker. A warm worker (:class:`WarmWorker`) also frees each
run before the next: a run's objects are reference cycles that only the cyclic
collector frees, and left to its own pace about ten runs' worlds (a 13.6 MB ``MjData``
each) were alive at once and the worker's RSS crept
(docs/adr/0029-sweep-memory-and-ray-state.md).
"""

from __future__ import annotations

import contextlib
import gc
import hashlib
import logging
import os
import signal
import socket
import threading
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from otonav.runtime._nodelog import LOGGER_NAME
from otonav.scenario import ScenarioConfig, run_scenario
from otonav.scenario._verdict import finite_figures
from otonav.stack import StackConfig
from otonav.sweep._plan import RunTask
from otonav.sweep._worlds import draw_world

Status = Literal["passed", "failed", "error"]

#: Test hook, comma-separated: ``crash:NAME`` (SIGKILL itself), ``hang:NAME`` (block
#: forever) or ``raise:NAME`` as a worker starts a run of scenario NAME. For the sweep's
#: own tests of crashed and hung workers; unset in normal use.
FAULT_ENV = "OTONAV_SWEEP_FAULT"

RECORDING = "recording.mcap"
PLOT = "trajectory.png"


@dataclass(frozen=True, slots=True)
class RunOutcome:
    """What comes back from a worker for one run."""

    run_id: str
    status: Status
    reason: str
    figures: dict[str, Any]
    """The verdict's figures (JSON-safe: non-finite numbers are None)."""
    recording_sha256: str | None
    wall_time_s: float
    """Wall time of the whole run in the worker: world build to artifacts."""
    worker: str
    artifacts: dict[str, bytes] = field(default_factory=dict)
    """File name -> content, for runs the sweep keeps."""
    scenario_json: str | None = None
    """The scenario a generated world turned out to be (None: the task's own)."""


def worker_name() -> str:
    return f"{socket.gethostname()}:{os.getpid()}"


def _inject_fault(task: RunTask) -> None:
    for fault in filter(None, os.environ.get(FAULT_ENV, "").split(",")):
        kind, _, name = fault.partition(":")
        if name != task.scenario:
            continue
        if kind == "crash":
            os.kill(os.getpid(), signal.SIGKILL)
        elif kind == "hang":
            threading.Event().wait()
        elif kind == "raise":
            raise RuntimeError(f"injected fault ({FAULT_ENV}={fault})")


def _keeps(task: RunTask, status: Status) -> bool:
    return task.keep == "all" or (task.keep == "failures" and status != "passed")


class WarmWorker:
    """A process that has imported otonav and runs task after task (a process-pool
    worker, a Ray actor), freeing each run before the next.

    A run's objects (its session, actors, MuJoCo model and data, recorder) form
    reference cycles, so only the cyclic collector frees them: after each run, a
    collection. So that it looks at one run's objects and not at everything imported,
    what exists when the worker starts, and what the first run adds that outlives it
    (lazily imported modules, caches), is frozen out of the collector's sight
    (``gc.freeze``): ~1 ms a run instead of ~33 ms for a full collection."""

    def __init__(self, scratch: Path) -> None:
        self.scratch = scratch
        self.runs = 0
        _quiet_nodes()  # a process of its own: no console handler but Python's last resort
        gc.collect()
        gc.freeze()

    def run(self, task: RunTask) -> RunOutcome:
        outcome = execute(task, self.scratch)
        gc.collect()
        self.runs += 1
        if self.runs == 1:
            gc.freeze()
        return outcome


def _quiet_nodes() -> None:
    """A node's ``self.log`` lines stay on /rosout in the kept recordings: on a sweep's
    console they would be many runs' lines, none saying which run (ADR 0070)."""
    nodes = logging.getLogger(LOGGER_NAME)
    if not nodes.handlers:
        nodes.addHandler(logging.NullHandler())
        nodes.propagate = False


def execute(task: RunTask, scratch: Path) -> RunOutcome:
    """Run ``task`` with its files in ``scratch`` (reused by the next task). Never
    raises for a failing run or a broken scenario: that is an ``error`` outcome."""
    start = time.perf_counter()
    recording = scratch / RECORDING
    recording.unlink(missing_ok=True)
    (scratch / PLOT).unlink(missing_ok=True)  # the last run's: this one draws its own
    scenario_json: str | None = None
    labels: dict[str, Any] = {}
    try:
        _inject_fault(task)
        if task.world is not None:
            scenario_json, labels = draw_world(*task.world)
            scenario = ScenarioConfig.model_validate_json(scenario_json)
            if scenario.seed != task.seed:
                scenario = ScenarioConfig.model_validate(
                    {**scenario.model_dump(), "seed": task.seed}
                )
                scenario_json = scenario.model_dump_json()
        else:
            scenario = ScenarioConfig.model_validate_json(task.scenario_json)
        stack = StackConfig.model_validate_json(task.stack_json)
        verdict = run_scenario(
            scenario,
            stack,
            out_dir=scratch,
            # A kept run's plot, drawn by the run from its ground truth (as otonav run
            # draws it); the others draw none (a plot costs about a short run).
            plot=lambda v: _keeps(task, "passed" if v.passed else "failed"),
            wall_ceiling=task.wall_ceiling_s,
            source=f"scenario {task.scenario!r}",
        )
    except Exception as exc:  # a broken run is a result, not the end of the sweep
        last = traceback.extract_tb(exc.__traceback__)[-1:]
        where = f" ({Path(last[0].filename).name}:{last[0].lineno})" if last else ""
        status: Status = "error"
        reason = f"{type(exc).__name__}: {exc}{where}".replace("\n", " ")
        figures: dict[str, Any] = {}
        artifacts = _artifacts(recording, None) if task.keep != "none" else {}
    else:
        status, reason = "passed" if verdict.passed else "failed", verdict.reason
        figures = finite_figures(verdict.as_dict())
        for key in ("recording", "plot", "wall_time_s", "rtf", "scenario", "reason"):
            figures.pop(key, None)
        figures["sim_wall_s"] = verdict.wall_time_s
        figures.update(labels)
        artifacts = _artifacts(recording, scratch / PLOT) if _keeps(task, status) else {}
    return RunOutcome(
        run_id=task.run_id,
        status=status,
        reason=reason,
        figures=figures,
        recording_sha256=_sha256(recording),
        wall_time_s=time.perf_counter() - start,
        worker=worker_name(),
        artifacts=artifacts,
        scenario_json=scenario_json,
    )


def _sha256(path: Path) -> str | None:
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except FileNotFoundError:
        return None


def _artifacts(recording: Path, png: Path | None) -> dict[str, bytes]:
    """The recording and the trajectory plot: the run's own (ground truth), or for a run
    that ended in an error, one drawn from its recording (odometry: all it has)."""
    if not recording.exists():
        return {}
    out = {RECORDING: recording.read_bytes()}
    if png is not None and png.exists():
        out[PLOT] = png.read_bytes()
    elif png is not None:
        from otonav.scenario._replay import plot_recording

        with contextlib.suppress(Exception):  # a plot is a convenience; the recording is
            out[PLOT] = plot_recording(recording, png).read_bytes()  # the artifact
    return out
