"""Sweeps: a family of scenario runs (files, generated worlds, config grids, seeds) on a
pool of warm local workers or on Ray, with results that do not depend on the backend or
the worker count, written as they finish (resumable), and a report.

    from otonav.sweep import load_sweep, plan_runs, sweep_results

    async for record in sweep_results(plan_runs(load_sweep(path)), out=Path("out/s")):
        print(record["scenario"], record["status"])

Modules: ``spec`` (the sweep file), ``plan`` (expansion into runs), ``worker`` (one run,
whatever the backend), ``backends`` (inline, process, ray), ``runner`` (the driver:
resume, results, artifacts), ``results`` (results.jsonl), ``stats``/``report``/``plots``
(the report), ``api`` (iterating results from async code).
"""

from otonav.sweep._api import run_sweep, sweep_results
from otonav.sweep._plan import RunTask, plan_runs
from otonav.sweep._report import summarize, write_report
from otonav.sweep._runner import all_records, execute, make_backend, prepare
from otonav.sweep._spec import GenerateSpec, SweepSpec, load_sweep
from otonav.sweep._worker import RunOutcome

__all__ = (
    "GenerateSpec",
    "RunOutcome",
    "RunTask",
    "SweepSpec",
    "all_records",
    "execute",
    "load_sweep",
    "make_backend",
    "plan_runs",
    "prepare",
    "run_sweep",
    "summarize",
    "sweep_results",
    "write_report",
)
