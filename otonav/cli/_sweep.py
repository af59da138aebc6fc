"""``otonav sweep``: run a family of scenarios on a process pool or Ray, write results
as they finish (resumable), and report pass rates with intervals and a repro per
failure."""

from __future__ import annotations

import argparse
import contextlib
import json
import signal
import sys
import threading
import time
from collections.abc import Iterable, Iterator
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # the command's imports are in main(): --help stays fast
    from rich.console import Console
    from rich.progress import Progress

    from otonav.sweep._spec import Scalar, SweepSpec

DEFAULT_OUT = Path("out/sweep")
QUICK_FLAGS = {
    "--generate": "generate",
    "--density": "density",
    "--gen": "gen",
    "--scenario": "scenario",
    "--seeds": "seeds",
    "--set": "overrides",
    "--keep": "keep",
    "--config": "config",
}
"""The quick form's flags (and their dests): with a sweep file they are refused, not
ignored."""


def add_parser(commands: Any) -> None:
    p = commands.add_parser(
        "sweep",
        help="run a family of scenarios in parallel and report pass rates",
        description="Run every scenario x override x seed of SWEEP.yaml (or of the quick "
        "form's flags), write results.jsonl as runs finish, then summary.json and report.md.",
    )
    p.add_argument("sweep", nargs="?", type=Path, help="the sweep file (YAML)")
    p.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output dir (default out/sweep)")
    p.add_argument("--workers", type=int, help="parallel workers (default: the machine's cores)")
    p.add_argument("--backend", choices=("process", "ray", "inline"), default="process")
    p.add_argument("--ray-address", help="join this Ray cluster (default: start a local one)")
    p.add_argument("--resume", action="store_true", help="finish the sweep already in --out")
    p.add_argument(
        "--retry-errors", action="store_true", help="with --resume: rerun runs that errored"
    )
    p.add_argument(
        "--actor",
        dest="actors",
        action="append",
        default=[],
        metavar="MODULE:CLASS",
        help="launch your node in every run, e.g. --actor my_nodes:Wander (repeatable); "
        "vary its parameters as actors.wander.KEY in the overrides",
    )
    quick = p.add_argument_group("quick form (no sweep file)")
    quick.add_argument("--generate", type=int, metavar="N", help="N generated worlds")
    quick.add_argument("--density", help="generator parameter: obstacle density")
    quick.add_argument(
        "--gen", action="append", default=[], metavar="KEY=VALUE", help="generator parameter"
    )
    quick.add_argument(
        "--scenario", action="append", default=[], help="built-in scenario or file (repeatable)"
    )
    quick.add_argument("--seeds", type=int, metavar="N", help="seeds 0..N-1 for every scenario")
    quick.add_argument(
        "--config",
        metavar="STACK.yaml",
        help="the stack config every run starts from (your robot, your nodes), as "
        "otonav run --config; default: the built-in one",
    )
    quick.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=V1,V2",
        help="a stack override, or a grid of values (repeatable)",
    )
    quick.add_argument(
        "--keep", choices=("failures", "all", "none"), help="artifacts to keep (default failures)"
    )
    p.add_argument(
        "--bag",
        action="store_true",
        help="beside each kept recording, a rosbag2 bag directory (bag/: metadata.yaml + "
        "the recording) for ros2 bag and rosbags",
    )
    p.set_defaults(handler=main)


def _scalar(text: str, where: str) -> Scalar:
    import yaml

    from otonav.stack import _safe_yaml as safe_yaml
    from otonav.stack._files import ConfigFileError

    try:
        value = safe_yaml.load(text)  # within the config files' limits (depth, size)
    except safe_yaml.YamlLimitError as exc:
        raise ConfigFileError(f"{where}: {exc}") from None
    except yaml.YAMLError:
        return text
    return value if isinstance(value, bool | int | float | str) else text


def _pairs(items: list[str], flag: str) -> list[tuple[str, str]]:
    from otonav.stack._files import ConfigFileError

    pairs = []
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise ConfigFileError(f"{flag} {item!r}: expected KEY=VALUE")
        pairs.append((key.strip(), value))
    return pairs


def quick_spec(args: argparse.Namespace) -> SweepSpec:
    """The sweep the quick-form flags describe."""
    from otonav.stack._files import ConfigFileError
    from otonav.sweep._spec import GenerateSource, GenerateSpec, SeedRange, SweepSpec

    scenarios: list[str | GenerateSource] = list(args.scenario)
    if args.generate is not None:
        if args.generate <= 0:
            raise ConfigFileError(f"--generate {args.generate}: must be a count > 0")
        params: dict[str, Scalar | tuple[Scalar, ...]] = {
            k: _scalar(v, f"--gen {k}") for k, v in _pairs(args.gen, "--gen")
        }
        if args.density is not None:
            params["density"] = args.density
        scenarios.append(GenerateSource(generate=GenerateSpec(count=args.generate, params=params)))
    if not scenarios:
        raise ConfigFileError(
            "otonav sweep: give a sweep file, or --generate N / --scenario NAME (quick form)"
        )
    if args.seeds is not None and args.seeds <= 0:
        raise ConfigFileError(f"--seeds {args.seeds}: must be a count > 0")
    grid = {
        k: tuple(_scalar(v, f"--set {k}") for v in value.split(","))
        for k, value in _pairs(args.overrides, "--set")
    }
    return SweepSpec(
        name="quick",
        config=str(Path(args.config).resolve()) if getattr(args, "config", None) else None,
        scenarios=tuple(scenarios),
        overrides=grid,
        seeds=SeedRange(count=args.seeds) if args.seeds else None,
        keep=args.keep or "failures",
    )


@contextlib.contextmanager
def _stop_on_signals(stop: threading.Event) -> Iterator[list[int]]:
    """SIGINT and SIGTERM set ``stop`` (the sweep ends after writing what finished);
    yields the list of signals received."""
    received: list[int] = []

    def handler(signum: int, _frame: FrameType | None) -> None:
        received.append(signum)
        stop.set()

    previous = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield received
    finally:
        for s, h in previous.items():
            signal.signal(s, h)


class _Live:
    """The progress display: a rich bar with ETA and pass rate on a terminal, else one
    line per finished run on stderr (CI logs)."""

    def __init__(self, total: int, done: int, passed: int) -> None:
        self.total, self.done, self.passed = total, done, passed
        self.tty = sys.stderr.isatty()
        self.progress: Progress | None = None
        if self.tty:
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )

            self.progress = Progress(
                TextColumn("sweep"),
                BarColumn(),
                MofNCompleteColumn(),
                TextColumn("{task.fields[rate]}"),
                TimeElapsedColumn(),
                TextColumn("ETA"),
                TimeRemainingColumn(),
                console=Console(stderr=True),
                transient=False,
            )
            self.task = self.progress.add_task(
                "runs", total=total, completed=done, rate=self._rate()
            )

    def _rate(self) -> str:
        return f"pass {100 * self.passed / self.done:.1f} %" if self.done else "pass -"

    def __enter__(self) -> _Live:
        if self.progress is not None:
            self.progress.start()
        return self

    def __exit__(self, *exc: object) -> None:
        if self.progress is not None:
            self.progress.stop()

    def update(self, record: dict[str, Any]) -> None:
        self.done += 1
        self.passed += record["status"] == "passed"
        if self.progress is not None:
            self.progress.update(self.task, completed=self.done, rate=self._rate())
        else:
            status = record["status"].upper()
            detail = "" if record["status"] == "passed" else f": {record['reason']}"
            sets = " ".join(f"{k}={v}" for k, v in record["overrides"].items())
            print(
                f"sweep: [{self.done}/{self.total}] {status} {record['scenario']} "
                f"seed={record['seed']}{' ' + sets if sets else ''}{detail}",
                file=sys.stderr,
                flush=True,
            )


def print_summary(summary: dict[str, Any], console: Console) -> None:
    from rich.table import Table

    def pct(rate: dict[str, Any]) -> tuple[str, str, str]:
        if rate["rate"] is None:
            return (str(rate["runs"]), "-", "-")
        errors = f" ({rate['errors']} err)" if rate["errors"] else ""
        return (
            f"{rate['passed']}/{rate['runs']}{errors}",
            f"{100 * rate['rate']:.1f} %",
            f"{100 * rate['low']:.1f} - {100 * rate['high']:.1f} %",
        )

    table = Table(title=f"{summary['name']}: {summary['finished']}/{summary['planned']} runs")
    for col in ("group", "passed", "pass rate", "95 % CI (Wilson)"):
        table.add_column(col, justify="left" if col == "group" else "right")
    table.add_row("all runs", *pct(summary["pass_rate"]), style="bold")
    for family, rate in summary["by_family"].items():
        table.add_row(family, *pct(rate))
    for key, values in summary["by_override"].items():
        for value, rate in values.items():
            table.add_row(f"{key}={value}", *pct(rate))
    console.print(table)
    for key, label, unit in (
        ("time_to_goal_s", "time to goal", "s"),
        ("min_clearance_m", "min clearance", "m"),
    ):
        s = summary[key]
        if s["count"]:
            console.print(
                f"{label}: p50 {s['p50']:.3f} {unit}, p95 {s['p95']:.3f} {unit}, "
                f"max {s['max']:.3f} {unit} ({s['count']} runs)"
            )
    from rich.markup import escape

    for group in summary["failures"]:
        first = group["runs"][0]
        # The run's own words: the group's key masks its numbers (for grouping only).
        like = f" (and {group['count'] - 1} more like it)" if group["count"] > 1 else ""
        console.print(f"[red]{group['count']} x[/red] {escape(str(first['reason']))}{like}")
        if first["repro"]:
            console.print(f"    repro: {first['repro']}", soft_wrap=True)


_PLAN_FLAGS = {"SWEEP": "sweep", **QUICK_FLAGS, "--actor": "actors"}
"""What makes the plan (stored in sweep.json): the sweep file or the quick-form flags,
and the launched nodes."""


def _invocation(args: argparse.Namespace) -> dict[str, Any]:
    """The arguments that made this sweep's plan, as JSON (paths absolute)."""
    stored = {dest: getattr(args, dest) for dest in _PLAN_FLAGS.values()}
    for dest in ("sweep", "config"):
        if stored[dest] is not None:
            stored[dest] = str(Path(stored[dest]).resolve())
    return stored


def _resume_plan(args: argparse.Namespace) -> None:
    """``--resume``: with no plan arguments, take the stored ones; with some, refuse
    those that differ from the stored plan (one line naming them)."""
    from otonav.stack._files import ConfigFileError
    from otonav.sweep._results import PLAN

    try:
        stored = json.loads((args.out / PLAN).read_text()).get("invocation")
    except (OSError, ValueError):
        stored = None
    if not isinstance(stored, dict):
        return  # nothing stored (an older sweep): the arguments must be given again
    given = _invocation(args)
    if all(value in (None, []) for value in given.values()):
        for key, value in stored.items():
            setattr(args, key, Path(value) if key == "sweep" and value else value)
        return
    differ = [
        f"{flag} (stored {stored.get(dest)!r}, given {given[dest]!r})"
        for flag, dest in _PLAN_FLAGS.items()
        if given[dest] != stored.get(dest)
    ]
    if differ:
        raise ConfigFileError(
            f"--resume: {args.out} holds a sweep made with other arguments: "
            f"{'; '.join(differ)}; give the same ones, or none to resume it as stored"
        )


def main(args: argparse.Namespace) -> int:
    from otonav.record._outlock import lock_output

    with contextlib.ExitStack() as held:
        return _main(args, held, lock_output)


def _write_bags(out: Path, records: Iterable[dict[str, Any]]) -> None:
    """``--bag``: a bag directory beside every kept recording (after the sweep: the
    driver alone writes into ``--out``)."""
    from otonav.record._bag import write_bag_directory

    for record in records:
        folder = record.get("artifacts")
        recording = out / str(folder) / "recording.mcap" if folder else None
        if recording is not None and recording.exists():
            write_bag_directory(recording, recording.parent / "bag")


def _main(args: argparse.Namespace, held: contextlib.ExitStack, lock_output: Any) -> int:
    from otonav.cli._console import make_console
    from otonav.stack._files import ConfigFileError
    from otonav.sweep import _runner as runner
    from otonav.sweep._plan import plan_runs
    from otonav.sweep._report import summarize, write_report
    from otonav.sweep._results import RESULTS
    from otonav.sweep._spec import describe, load_sweep

    if args.workers is not None and args.workers <= 0:
        raise ConfigFileError(f"--workers {args.workers}: must be a count > 0")
    if args.retry_errors and not args.resume:
        raise ConfigFileError("--retry-errors: only with --resume")
    if args.resume:
        _resume_plan(args)  # the stored plan, so --resume --out DIR alone resumes
    if args.sweep is not None:
        quick = [f for f, dest in QUICK_FLAGS.items() if getattr(args, dest) not in (None, [])]
        if quick:  # they were silently ignored (issue 27)
            raise ConfigFileError(
                f"{' '.join(quick)}: quick-form flags, not used with a sweep file "
                f"({args.sweep}); put them in the file, or drop the file"
            )
        spec = load_sweep(args.sweep)
        tasks = plan_runs(spec, base=args.sweep.parent, where=str(args.sweep), actors=args.actors)
    else:
        spec = quick_spec(args)
        tasks = plan_runs(spec, where="otonav sweep", actors=args.actors)
    from otonav.sweep._precheck import check_tasks

    problems = check_tasks(tasks)  # before the first run, not as late "error" runs
    if problems:
        for line in problems:
            print(f"otonav: error: {line}", file=sys.stderr)
        print(
            f"otonav: {len(problems)} scenario(s) of the sweep cannot run; nothing was run",
            file=sys.stderr,
        )
        return 2
    held.enter_context(lock_output(args.out))  # one sweep per --out (issue 27)
    backend = runner.make_backend(args.backend, workers=args.workers, ray_address=args.ray_address)
    prepared = runner.prepare(
        args.out,
        tasks,
        resume=args.resume,
        retry_errors=args.retry_errors,
        meta={"name": spec.name, "spec": describe(spec), "invocation": _invocation(args)},
    )
    console = make_console()
    stop = threading.Event()
    passed_before = sum(r["status"] == "passed" for r in prepared.finished.values())
    start = time.perf_counter()
    live = _Live(len(tasks), len(prepared.finished), passed_before)
    with _stop_on_signals(stop) as received, live:
        runner.execute(prepared, backend, stop=stop, on_record=live.update)
    wall = time.perf_counter() - start
    records = runner.all_records(prepared)
    summary = summarize(records, planned=len(tasks), name=spec.name)
    ran = len(prepared.pending)
    summary["this_invocation"] = {"wall_time_s": wall, "backend": backend.name, "pending": ran}
    report = write_report(args.out, summary, records)
    if args.bag:
        _write_bags(args.out, records)
    print_summary(summary, console)
    console.print(f"results: {args.out / RESULTS}\nreport:  {report}")
    if received:
        print(
            f"otonav: sweep interrupted; {summary['finished']} of {len(tasks)} runs are "
            f"recorded in {args.out}; finish with --resume",
            file=sys.stderr,
        )
        return 143 if received[-1] == signal.SIGTERM else 130
    return 0 if summary["pass_rate"]["passed"] == len(tasks) else 1
