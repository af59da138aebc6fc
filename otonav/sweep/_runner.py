"""The driver: decides what still has to run in ``--out``, hands it to a backend, and
writes each result as it arrives (kept artifacts first, then the record), so the
results file never names an artifact that is not there."""

from __future__ import annotations

import hashlib
import json
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from otonav.stack._files import ConfigFileError
from otonav.sweep._plan import RunTask
from otonav.sweep._results import (
    PLAN,
    RESULTS,
    RUNS,
    ResultsFile,
    compact_results,
    latest_by_run,
    make_record,
    read_results,
)
from otonav.sweep._worker import RunOutcome
from otonav.sweep.backends import Backend

OnRecord = Callable[[dict[str, Any]], None]


def fingerprint(tasks: Sequence[RunTask]) -> str:
    """What identifies a sweep for ``--resume``: its set of runs."""
    return hashlib.sha256("\n".join(sorted(t.run_id for t in tasks)).encode()).hexdigest()


@dataclass(frozen=True)
class Prepared:
    """A sweep bound to its output directory."""

    out: Path
    tasks: tuple[RunTask, ...]
    pending: tuple[RunTask, ...]
    """The runs still to do (all of them unless resuming)."""
    finished: dict[str, dict[str, Any]]
    """run_id -> record of the runs finished by an earlier, interrupted invocation."""
    resumed: bool = False
    """``out`` held this sweep's results already (a retried run may append a second line)."""


def prepare(
    out: Path,
    tasks: Sequence[RunTask],
    *,
    resume: bool = False,
    retry_errors: bool = False,
    meta: dict[str, Any] | None = None,
) -> Prepared:
    """Check ``out`` and write ``sweep.json``. Without ``resume``, ``out`` must not hold
    a sweep; with it, it must hold this one (the same runs), and finished runs are not
    run again (nor runs that ended in an error, unless ``retry_errors``)."""
    plan_file, results_file = out / PLAN, out / RESULTS
    print_ = fingerprint(tasks)
    finished: dict[str, dict[str, Any]] = {}
    if plan_file.exists() or results_file.exists():
        if not resume:
            raise ConfigFileError(
                f"--out {out}: already holds a sweep; add --resume to finish it, "
                "or choose another --out"
            )
        try:
            previous = json.loads(plan_file.read_text()).get("fingerprint")
        except (OSError, ValueError):
            previous = None
        if previous != print_:
            raise ConfigFileError(
                f"--resume: {out} holds a different sweep (its runs are not this sweep's); "
                "resume it with the sweep file that started it, or choose another --out"
            )
        compact_results(results_file)  # a killed retry may have left two lines for a run
        ids = {t.run_id for t in tasks}
        finished = {
            rid: r
            for rid, r in latest_by_run(read_results(results_file)).items()
            if rid in ids and (r.get("status") != "error" or not retry_errors)
        }
    out.mkdir(parents=True, exist_ok=True)
    plan_file.write_text(
        json.dumps({**(meta or {}), "runs": len(tasks), "fingerprint": print_}, indent=2) + "\n"
    )
    pending = tuple(t for t in tasks if t.run_id not in finished)
    resumed = results_file.exists()
    return Prepared(out, tuple(tasks), pending, finished, resumed)


def _write_artifacts(
    out: Path, task: RunTask, outcome: RunOutcome
) -> tuple[str | None, str | None]:
    """Write a kept run's files under ``runs/<run_id>/``; return (that dir, the scenario
    file), relative to ``out``.

    A generated world that did not pass keeps its ``scenario.yaml`` (~1 kB) even with
    ``keep: none``: its repro line runs that file, since ``otonav run`` cannot draw
    worlds (docs/adr/0029-sweep-memory-and-ray-state.md)."""
    scenario_json = outcome.scenario_json or task.scenario_json
    repro_needs_it = task.world is not None and outcome.status != "passed"
    if not scenario_json or not (outcome.artifacts or repro_needs_it):
        return None, None
    rel = Path(RUNS) / task.run_id
    folder = out / rel
    folder.mkdir(parents=True, exist_ok=True)
    for name, data in outcome.artifacts.items():
        (folder / name).write_bytes(data)
    scenario = yaml.safe_dump(json.loads(scenario_json), sort_keys=False)
    (folder / "scenario.yaml").write_text(scenario)
    return str(rel), str(out / rel / "scenario.yaml")


def execute(
    prepared: Prepared,
    backend: Backend,
    *,
    stop: threading.Event | None = None,
    on_record: OnRecord | None = None,
) -> list[dict[str, Any]]:
    """Run the pending runs on ``backend``; append each record as it finishes and hand
    it to ``on_record``. Returns this invocation's records. Setting ``stop`` ends the
    sweep early: finished records are all on disk, runs in flight are not recorded."""
    stop = stop or threading.Event()
    results = ResultsFile(prepared.out / RESULTS)
    records: list[dict[str, Any]] = []

    def emit(task: RunTask, outcome: RunOutcome) -> None:
        folder, scenario_file = _write_artifacts(prepared.out, task, outcome)
        record = make_record(task, outcome, folder, scenario_file)
        results.append(record)
        records.append(record)
        if on_record is not None:
            on_record(record)

    try:
        if prepared.pending:
            backend.run(prepared.pending, emit, stop)
    finally:
        results.close()
        if prepared.resumed:
            compact_results(prepared.out / RESULTS)  # a retried run: its latest line only
    return records


def all_records(prepared: Prepared) -> list[dict[str, Any]]:
    """The latest record of every planned run found in ``out``, in sweep order."""
    ids = {t.run_id for t in prepared.tasks}
    latest = latest_by_run(read_results(prepared.out / RESULTS))
    return sorted((r for rid, r in latest.items() if rid in ids), key=lambda r: r["index"])


def make_backend(
    name: str, *, workers: int | None = None, ray_address: str | None = None
) -> Backend:
    """``inline``, ``process`` (default) or ``ray``."""
    if name == "inline":
        from otonav.sweep.backends._inline import InlineBackend

        return InlineBackend()
    if name == "process":
        from otonav.sweep.backends._process import ProcessBackend

        return ProcessBackend(workers)
    if name == "ray":
        from otonav.sweep.backends._ray import RayBackend

        return RayBackend(workers, address=ray_address)
    raise ConfigFileError(f"--backend {name!r}: valid backends are process, ray, inline")
