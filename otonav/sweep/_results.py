"""``results.jsonl``: one JSON object per finished run, appended and flushed as it
finishes, so an interrupted sweep (Ctrl-C, SIGTERM, a kill) loses no finished result.
A kill in the middle of a write leaves at most one partial last line; reading drops it
(and the next append starts on a fresh line).

A run retried with ``--retry-errors`` appends its new record; once the sweep ends (and
when a later ``--resume`` finds one left by a killed sweep) the file is rewritten with
one line per run, the latest, so ``jq`` or pandas see no duplicates (issue 27)."""

from __future__ import annotations

import json
import os
import shlex
from collections.abc import Iterable
from pathlib import Path
from typing import IO, Any

from otonav.sweep._plan import RunTask, format_value
from otonav.sweep._worker import RunOutcome

RESULTS = "results.jsonl"
PLAN = "sweep.json"
RUNS = "runs"


def read_results(path: Path) -> list[dict[str, Any]]:
    """Every complete record in ``path``, in file order (a cut-off last line skipped)."""
    if not path.exists():
        return []
    records = []
    for line in path.read_text().splitlines():
        try:
            record = json.loads(line)
        except json.JSONDecodeError:
            continue  # a line cut by a kill mid-write: that run is simply not finished
        if isinstance(record, dict) and "run_id" in record:
            records.append(record)
    return records


def latest_by_run(records: Iterable[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """run_id -> its last record (a retried run appends a newer one)."""
    return {r["run_id"]: r for r in records}


def compact_results(path: Path) -> int:
    """Rewrite ``path`` with one line per run, its latest record, where the latest
    stands in the file (atomically: a kill leaves the old file or the new one). Returns
    how many superseded lines were dropped (0: the file is left untouched)."""
    records = read_results(path)
    latest: dict[str, dict[str, Any]] = {}
    for record in records:
        latest.pop(record["run_id"], None)  # the newer one takes the later place
        latest[record["run_id"]] = record
    dropped = len(records) - len(latest)
    if dropped == 0:
        return 0
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "w") as f:
        f.writelines(json.dumps(r, sort_keys=True) + "\n" for r in latest.values())
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)
    return dropped


def repro_command(task: RunTask, scenario_file: str | None) -> str | None:
    """The one line that reruns ``task`` alone with ``otonav run``."""
    source = task.source or scenario_file
    if source is None:
        return None
    parts = ["otonav", "run", "--scenario", source, "--seed", str(task.seed)]
    if task.config:
        parts += ["--config", task.config]
    for spec in task.actors:
        parts += ["--actor", spec]
    for key, value in task.overrides:
        parts += ["--set", f"{key}={format_value(value)}"]
    return shlex.join(parts)


def make_record(
    task: RunTask, outcome: RunOutcome, artifacts_dir: str | None, scenario_file: str | None
) -> dict[str, Any]:
    return {
        "run_id": task.run_id,
        "index": task.index,
        "scenario": task.scenario,
        "family": task.family,
        "seed": task.seed,
        "overrides": {k: v for k, v in task.overrides},
        "status": outcome.status,
        "passed": outcome.status == "passed",
        "reason": outcome.reason,
        **outcome.figures,
        "recording_sha256": outcome.recording_sha256,
        "wall_time_s": outcome.wall_time_s,
        "worker": outcome.worker,
        "artifacts": artifacts_dir,
        "repro": repro_command(task, scenario_file),
    }


class ResultsFile:
    """Appends records to ``results.jsonl``, one flushed line each."""

    def __init__(self, path: Path) -> None:
        self.path = path
        needs_newline = path.exists() and path.stat().st_size > 0 and not _ends_with_newline(path)
        self._file: IO[str] = open(path, "a")  # noqa: SIM115 - closed in close()
        if needs_newline:  # the previous sweep was killed mid-line
            self._file.write("\n")

    def append(self, record: dict[str, Any]) -> None:
        self._file.write(json.dumps(record, sort_keys=True) + "\n")
        self._file.flush()

    def close(self) -> None:
        self._file.close()


def _ends_with_newline(path: Path) -> bool:
    with open(path, "rb") as f:
        f.seek(-1, 2)
        return f.read(1) == b"\n"
