"""``otonav run``: run a scenario headless in virtual time, print the verdict."""

from __future__ import annotations

import argparse
import asyncio
import json
import sys
from pathlib import Path
from typing import Any

from pydantic import ValidationError
from rich.console import Console
from rich.table import Table

from otonav.cli.progress import ProgressLine
from otonav.cli.signals import StopOnSignals
from otonav.runtime import WallClockCeilingError
from otonav.scenario import ScenarioConfig, Verdict, run_scenario
from otonav.scenario.builtin import BUILTIN
from otonav.scenario.realtime import run_scenario_realtime
from otonav.scenario.run import finite_figures
from otonav.stack import StackConfig
from otonav.stack.files import ConfigFileError, describe_validation_error, load_model
from otonav.stack.limits import check_scale
from otonav.stack.overrides import apply_overrides

DEFAULT_OUT = Path("out")


def add_parser(commands: Any) -> None:
    p = commands.add_parser("run", help="run a scenario (default: acceptance) headless")
    p.add_argument("--scenario", default="acceptance", help="built-in name or YAML path")
    p.add_argument("--config", type=Path, help="stack config YAML (default: built-in)")
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY.PATH=VALUE",
        help="override a stack config key, e.g. --set nav.kp_lin=0 (repeatable)",
    )
    p.add_argument("--seed", type=int, help="override the scenario's seed")
    p.add_argument(
        "--out", type=Path, default=DEFAULT_OUT, help="artifact directory (default: out)"
    )
    p.add_argument("--no-record", action="store_true", help="do not write recording.mcap")
    p.add_argument(
        "--realtime", action="store_true", help="pace sim time to the wall clock (same actors)"
    )
    p.add_argument(
        "--scale",
        type=float,
        default=1.0,
        help="with --realtime/--gui: sim seconds per wall second",
    )
    p.add_argument("--gui", action="store_true", help="show the run in MuJoCo's viewer (real time)")
    p.set_defaults(handler=main)


def load_scenario(spec: str) -> ScenarioConfig:
    if spec in BUILTIN:
        return BUILTIN[spec]
    path = Path(spec)
    if path.suffix in (".yaml", ".yml") or path.exists():
        return load_model(path, ScenarioConfig)
    raise ConfigFileError(
        f"--scenario {spec!r}: not a built-in scenario ({', '.join(BUILTIN)}) nor a YAML file"
    )


def load_stack(config: Path | None, overrides: list[str]) -> StackConfig:
    stack = load_model(config, StackConfig) if config is not None else StackConfig()
    return apply_overrides(stack, overrides) if overrides else stack


def print_verdict(verdict: Verdict, console: Console) -> None:
    table = Table(
        title=f"scenario {verdict.scenario}: " + ("PASSED" if verdict.passed else "FAILED")
    )
    table.add_column("figure")
    table.add_column("value", justify="right")
    ttg = f"{verdict.time_to_goal_s:.2f} s" if verdict.time_to_goal_s is not None else "-"
    for key, value in (
        ("reached", "yes" if verdict.reached else "no"),
        ("time to goal", ttg),
        ("min clearance", f"{verdict.min_clearance_m:.3f} m"),
        ("final distance", f"{verdict.final_distance_m:.3f} m"),
        ("path length", f"{verdict.path_length_m:.2f} m"),
        ("sim time", f"{verdict.sim_time_s:.2f} s"),
        ("wall time", f"{verdict.wall_time_s:.3f} s"),
        ("real-time factor", f"{verdict.rtf:.0f}x"),
    ):
        table.add_row(key, value)
    console.print(table)
    console.print(f"why: {verdict.reason}")
    for label, path in (("recording", verdict.recording), ("plot", verdict.plot)):
        if path:
            console.print(f"{label}: {path}")


def main(args: argparse.Namespace) -> int:
    with StopOnSignals() as guard:
        return _main(args, guard)


def _main(args: argparse.Namespace, guard: StopOnSignals) -> int:
    scenario = load_scenario(args.scenario)
    if args.seed is not None:  # validated like the file (model_copy would not check it)
        try:
            scenario = ScenarioConfig.model_validate({**scenario.model_dump(), "seed": args.seed})
        except ValidationError as exc:
            raise ConfigFileError(describe_validation_error("--seed", exc)) from None
    stack = load_stack(args.config, args.overrides)
    out: Path = args.out
    source = args.scenario if args.scenario not in BUILTIN else f"scenario '{args.scenario}'"
    progress = ProgressLine() if sys.stderr.isatty() else None
    guard.arm()  # from here a signal stops the run and lets it finish its artifacts
    try:
        if args.gui or args.realtime:
            problem = check_scale(args.scale)
            if problem is not None:
                raise ConfigFileError(problem)
            verdict = run_scenario_realtime(
                scenario,
                stack,
                out_dir=out,
                record=not args.no_record,
                scale=args.scale,
                gui=args.gui,
                on_start=guard.attach,
            )
        else:
            verdict = run_scenario(
                scenario,
                stack,
                out_dir=out,
                record=not args.no_record,
                progress=progress,
                source=source,
                on_start=guard.attach,
            )
    except asyncio.CancelledError:
        if guard.received is not None:
            return guard.report()
        print("otonav: terminated; the recording was finished and is readable", file=sys.stderr)
        return 143
    except WallClockCeilingError as exc:
        # A run that outlasts its wall-clock ceiling is a failed run, not a crash: the
        # recording and the plot were finished on the way out.
        kept = [str(out / name) for name in ("recording.mcap", "trajectory.png")]
        kept = [path for path in kept if Path(path).exists()]
        print(
            f"otonav: error: {exc}" + (f"; kept {', '.join(kept)}" if kept else ""),
            file=sys.stderr,
        )
        return 1
    finally:
        if progress is not None:
            progress.clear()
    if guard.received is not None:  # the run had ended; the signal came while saving
        return guard.report()
    out.mkdir(parents=True, exist_ok=True)
    summary = out / "summary.json"
    summary.write_text(json.dumps(finite_figures(verdict.as_dict()), indent=2, default=str) + "\n")
    console = Console(highlight=False)
    print_verdict(verdict, console)
    console.print(f"summary: {summary}")
    return 0 if verdict.passed else 1
