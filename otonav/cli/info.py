"""``otonav info FILE`` (like ``ros2 bag info``) and ``otonav salvage IN OUT``."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any


def add_parser(commands: Any) -> None:
    p = commands.add_parser("info", help="topics, types, counts, rates, duration of a recording")
    p.add_argument("file", type=Path)
    p.set_defaults(handler=info_main)
    s = commands.add_parser("salvage", help="rewrite a cut-off recording as an indexed file")
    s.add_argument("source", type=Path)
    s.add_argument("target", type=Path)
    s.set_defaults(handler=salvage_main)


def info_main(args: argparse.Namespace) -> int:
    from rich.console import Console
    from rich.table import Table

    from otonav.record.reader import summarize

    summary = summarize(args.file)
    console = Console(highlight=False)
    if summary.truncated:
        print(
            f"otonav: warning: {args.file} was cut off (no index): showing the "
            f"{summary.message_count} messages of its complete chunks; "
            f"'otonav salvage {args.file} FIXED.mcap' rewrites them as an indexed file",
            file=sys.stderr,
        )
    console.print(f"file:      {summary.path} ({summary.size_bytes / 1024:.1f} KiB)")
    console.print(f"profile:   {summary.profile or '-'}   library: {summary.library or '-'}")
    console.print(
        f"duration:  {summary.duration_s:.3f} s  "
        f"(sim time {summary.start_ns / 1e9:.3f} .. {summary.end_ns / 1e9:.3f})"
    )
    console.print(f"messages:  {summary.message_count}")
    table = Table()
    for column in ("topic", "type", "count", "rate (Hz)"):
        table.add_column(column, justify="right" if column in ("count", "rate (Hz)") else "left")
    for t in summary.topics:
        table.add_row(t.topic, t.type, str(t.count), f"{t.rate_hz:.1f}")
    console.print(table)
    verdict = summary.metadata.get("otonav", {}).get("verdict")
    if verdict:
        console.print(f"verdict:   {verdict}")
    return 0


def salvage_main(args: argparse.Namespace) -> int:
    from otonav.record.salvage import salvage

    count = salvage(args.source, args.target)
    print(f"salvaged {count} messages from {args.source} into {args.target}")
    return 0
