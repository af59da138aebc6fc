"""``otonav replay RECORDING --node NAME``: re-simulate actors against a recording and
compare their outputs with it. Exit 0: no divergence beyond the tolerance; 1: diverged
(or a replayed actor crashed); 2: bad input (one line)."""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import math
import signal
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from rich.console import Console

    from otonav.cli._signals import StopOnSignals
    from otonav.replay import ReplayResult


def add_parser(commands: Any) -> None:
    p = commands.add_parser(
        "replay",
        help="re-simulate actors against a recording and compare their outputs",
        description=(
            "Bring up only the named actors on virtual time, feed them the recording's "
            "inputs at the recorded instants and order, compare what they publish with "
            "the recording. Exit 0: same (within --tolerance); 1: diverged; 2: bad input."
        ),
    )
    p.add_argument("recording", type=Path, help="an MCAP recording (e.g. out/recording.mcap)")
    p.add_argument(
        "--node",
        dest="nodes",
        action="append",
        default=[],
        metavar="NAME",
        help="actor to replay: a stack actor (nav, base, ...) or package.module:Name; "
        "repeatable or comma-separated",
    )
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY.PATH=VALUE",
        help="change the recorded stack config for the replay, e.g. --set nav.kp_ang=3.0",
    )
    p.add_argument(
        "--tolerance",
        type=float,
        default=0.0,
        metavar="ABS",
        help="absolute tolerance for float fields (default 0: any difference diverges)",
    )
    p.add_argument(
        "--out", type=Path, help="write an MCAP with the replayed outputs beside the inputs"
    )
    p.add_argument(
        "--bag",
        action="store_true",
        help="with --out: also a rosbag2 bag directory beside it (OUT without .mcap, plus "
        "_bag: metadata.yaml + the written MCAP)",
    )
    p.add_argument(
        "--wake",
        choices=("timers", "recorded"),
        default="timers",
        help="when the actors wake: on their own timers (default; exact for virtual-time "
        "recordings), or at the instants their outputs were recorded (for a recording made "
        "in real time, where wake-ups followed the wall clock)",
    )
    p.set_defaults(handler=main)


def replay_bag_path(written: Path) -> Path:
    """``--bag``: ``replayed.mcap`` -> the directory ``replayed_bag`` beside it."""
    return written.with_name(f"{written.stem}_bag")


def main(args: argparse.Namespace) -> int:
    from otonav.record._outlock import lock_output
    from otonav.stack._files import ConfigFileError

    nodes = [name.strip() for spec in args.nodes for name in spec.split(",") if name.strip()]
    if not nodes:
        raise ConfigFileError("--node: name a node to replay, e.g. --node nav")
    if args.bag and args.out is None:
        raise ConfigFileError("--bag: only with --out (the bag holds the written MCAP)")
    if not (math.isfinite(args.tolerance) and args.tolerance >= 0):
        raise ConfigFileError(f"--tolerance {args.tolerance}: must be a finite number >= 0")
    from otonav.cli._signals import EXIT_CODES, StopOnSignals

    # The first SIGINT/SIGTERM cancels the replay (its loop shuts down as a run's does) or,
    # once it has ended, abandons the output (it is all or nothing); a second is noted.
    with StopOnSignals("the replay's output") as stop, contextlib.ExitStack() as held:
        existed = args.out is not None and args.out.exists()
        if args.out is not None:  # one writer per file (issue 27)
            held.enter_context(lock_output(args.out, is_file=True))
        written: list[Path] = []
        try:
            return _replay(args, nodes, stop, written)
        except (KeyboardInterrupt, asyncio.CancelledError):
            sig = stop.received or signal.SIGINT
            if args.out is None:
                what = "nothing was written"
            elif written:
                what = f"{args.out} was written before it (finished and indexed)"
                if args.bag and len(written) < 2:
                    what += f"; its bag {replay_bag_path(args.out)} was not finished"
            else:
                before = "the earlier file there is as it was" if existed else "no file there"
                what = f"{args.out} was not written ({before})"
            print(f"otonav: {sig.name}: the replay stopped; {what}", file=sys.stderr)
            return EXIT_CODES[sig]


def _replay(
    args: argparse.Namespace, nodes: list[str], stop: StopOnSignals, written_to: list[Path]
) -> int:
    from otonav.cli._console import make_console
    from otonav.replay import ReplayInputError, replay_recording
    from otonav.replay._output import write_replay
    from otonav.stack._files import ConfigFileError

    try:
        stop.arm()
        result = replay_recording(
            args.recording,
            nodes,
            overrides=args.overrides,
            tolerance=args.tolerance,
            wake=args.wake,
            on_start=stop.attach,
        )
        stop.disarm()
        written = write_replay(result, args.out) if args.out is not None else None
        written_to.extend([written] if written is not None else [])
    except ReplayInputError as exc:
        raise ConfigFileError(str(exc)) from None
    except ValueError as exc:  # --out on the input file
        raise ConfigFileError(str(exc)) from None
    console = make_console()
    print_result(result, console)
    if written is not None:
        console.print(f"written: {written} (replayed outputs; recorded ones under /recorded/...)")
        if args.bag:
            from otonav.record._bag import write_bag_directory

            bag = write_bag_directory(Path(written), replay_bag_path(Path(written)))
            written_to.append(bag)
            console.print(f"bag: {bag}")
    return 0 if result.passed else 1


def print_result(result: ReplayResult, console: Console) -> None:
    fed = ", ".join(f"{topic} {count}" for topic, count in sorted(result.inputs.items()))
    console.print(
        f"replayed {', '.join(result.nodes)} against {result.recording}: "
        f"{result.sim_time_s:.3f} s of sim time in {result.wall_time_s:.3f} s "
        f"({result.rtf:.0f}x; CPU {result.cpu_time_s:.3f} s); fed {fed}"
    )
    for t in result.topics:
        line = (
            f"  {t.topic}: {t.recorded} recorded, {t.replayed} replayed, {t.identical} "
            f"byte-identical, {t.differing} differ"
        )
        if t.within_tolerance:
            line += f", {t.within_tolerance} within the tolerance"
        if t.missing or t.extra:
            line += f", {t.missing} missing, {t.extra} extra"
        if t.max_diff_field and math.isinf(t.max_abs_diff) and t.max_diff_values:
            recorded, replayed = t.max_diff_values  # text, or a length: no |diff| to print
            line += f" (at {t.max_diff_field}: recorded {recorded!r}, replayed {replayed!r})"
        elif t.max_diff_field:
            line += f" (largest |diff| {t.max_abs_diff:.6g} at {t.max_diff_field})"
        console.print(line)
    if result.crash is not None:
        console.print(f"CRASHED: {result.crash.splitlines()[0]}")
        print(result.crash, file=sys.stderr)
    first = result.first_divergence
    if result.format_change is not None:
        console.print(f"note: {result.format_change}")
    if first is not None and result.format_change is not None:
        console.print(f"first difference: {first}")
        console.print(
            f"FORMAT DIFFERS: {len(result.divergences)} message(s) beyond the tolerance, "
            "which the format change above can explain: record the run again with this "
            "otonav before you compare"
        )
    elif first is not None:
        console.print(f"first divergence: {first}")
        console.print(f"DIVERGED: {len(result.divergences)} message(s) beyond the tolerance")
        if all(d.kind != "content" for d in result.divergences):
            console.print(
                "(only timing differs: if the recording was made in real time, try --wake recorded)"
            )
    elif result.crash is None:
        verdict = "byte-identical" if result.byte_identical else "same within the tolerance"
        console.print(f"SAME: every output {verdict}")
