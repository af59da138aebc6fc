"""``otonav bench``: measure the stack against bare physics (see otonav.bench)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any


def add_parser(commands: Any) -> None:
    p = commands.add_parser("bench", help="stack vs bare physics: wall time, RTF, ratios, RSS")
    p.add_argument("--duration", type=float, default=30.0, help="sim seconds per run (default 30)")
    p.add_argument("--reps", type=int, default=5, help="runs per configuration (default 5)")
    p.add_argument("--json", type=Path, default=Path("out/bench.json"), help="write figures here")
    p.add_argument("--no-scaling", action="store_true", help="skip the beams / subscribers tables")
    p.add_argument(
        "--clutter",
        action="store_true",
        help="also the clutter curve (RTF with 0 to 3000 boxes, otonav.bench._clutter; "
        "several minutes: also benchmarks/clutter_bench.py)",
    )
    p.add_argument("--clutter-reps", type=int, default=5, help="runs per box count (default 5)")
    p.add_argument(
        "--quick",
        action="store_true",
        help="2 s, 1 run, no scaling, one child process for all: checks it runs",
    )
    p.add_argument(
        "--long",
        type=float,
        metavar="SECONDS",
        help="instead: memory over one long run of the stack + recorder (e.g. 600): RSS, "
        "Python heap and file size every 60 s of sim",
    )
    p.set_defaults(handler=main)


def main(args: argparse.Namespace) -> int:
    from otonav.bench._clutter import COUNTS as CLUTTER_COUNTS
    from otonav.bench._report import format_report, run_bench, write_json
    from otonav.stack._files import ConfigFileError

    if args.long is not None:
        from otonav.bench._memory import format_long, run_long

        if not 0 < args.long <= 86_400:
            print(
                f"otonav bench: --long must be in (0, 86400] s of sim time, got {args.long:g}",
                file=sys.stderr,
            )
            return 2
        memory = run_long(args.long, every=min(60.0, args.long))
        print(format_long(memory))
        write_json(memory, args.json)
        print(f"figures: {args.json}")
        return 0
    duration, reps, scaling = args.duration, args.reps, not args.no_scaling
    # -1 ran, printed a -53x RTF and overwrote out/bench.json with it (issue 27).
    if not 0 < duration <= 86_400:
        raise ConfigFileError(f"--duration {duration:g}: must be in (0, 86400] s of sim time")
    if not 1 <= reps <= 1000:
        raise ConfigFileError(f"--reps {reps}: must be in [1, 1000]")
    clutter: tuple[tuple[int, ...], int] | None = None
    if args.clutter:
        clutter = (CLUTTER_COUNTS, args.clutter_reps)
    if args.quick:
        duration, reps, scaling = 2.0, 1, False
        clutter = None if clutter is None else ((0, 100), 1)
    result = run_bench(
        duration,
        reps,
        scaling=scaling,
        profile=not args.quick,
        clutter=clutter,
        fresh=not args.quick,
    )
    print(format_report(result))
    write_json(result, args.json)
    print(f"figures: {args.json}")
    return 0
