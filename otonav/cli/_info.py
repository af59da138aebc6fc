"""``otonav info FILE`` (like ``ros2 bag info``) and ``otonav salvage IN OUT``."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from otonav.record._reader import RecordingSummary


def add_parser(commands: Any) -> None:
    p = commands.add_parser("info", help="topics, types, counts, rates, duration of a recording")
    p.add_argument("file", type=Path)
    p.add_argument("--json", action="store_true", help="print the facts as one JSON object")
    p.set_defaults(handler=info_main)
    s = commands.add_parser("salvage", help="rewrite a cut-off recording as an indexed file")
    s.add_argument("source", type=Path)
    s.add_argument("target", type=Path)
    s.add_argument("--force", action="store_true", help="overwrite TARGET if it exists")
    s.set_defaults(handler=salvage_main)


def warn_cut_off(summary: RecordingSummary, doing: str) -> None:
    """One line on stderr: the file was cut off (and what is damaged besides), what is
    used, how to fix it."""
    damaged = ""
    if summary.damaged:
        from otonav.record._verify import describe_damage

        damaged = f" and {describe_damage(summary.path, summary.damaged).split(': ', 1)[1]}"
    print(
        f"otonav: warning: {summary.path} was cut off (no index){damaged}: {doing} the "
        f"{summary.message_count} messages of its intact complete chunks; "
        f"'otonav salvage {summary.path} FIXED.mcap' rewrites them as an indexed file",
        file=sys.stderr,
    )


def warn_damaged(summary: RecordingSummary, doing: str) -> bool:
    """One line on stderr if chunks failed their CRC (a cut-off file's are in
    :func:`warn_cut_off`'s line); True if there were any."""
    if not summary.damaged:
        return False
    if summary.truncated:
        return True
    from otonav.record._verify import describe_damage

    print(
        f"otonav: warning: {describe_damage(summary.path, summary.damaged)}; {doing} the "
        "intact chunks only; 'otonav salvage' copies them into a new file",
        file=sys.stderr,
    )
    return True


def _decoded(value: str) -> Any:
    try:
        return json.loads(value)
    except ValueError:
        return value


def as_json(summary: RecordingSummary) -> dict[str, Any]:
    """The facts of ``otonav info`` as plain data (``--json``): JSON-valued metadata
    fields (configs, the verdict, the world's boxes) are decoded."""
    run = summary.metadata.get("otonav", {})
    return {
        "file": str(summary.path),
        "size_bytes": summary.size_bytes,
        "profile": summary.profile,
        "library": summary.library,
        "truncated": summary.truncated,
        "damaged": [d.describe() for d in summary.damaged],
        "start_s": summary.start_ns / 1e9,
        "end_s": summary.end_ns / 1e9,
        "duration_s": summary.duration_s,
        "message_count": summary.message_count,
        "topics": [
            {"topic": t.topic, "type": t.type, "count": t.count, "rate_hz": t.rate_hz}
            for t in summary.topics
        ],
        "scenario": run.get("scenario"),
        "seed": int(run["seed"]) if run.get("seed", "").isdigit() else None,
        "metadata": {
            name: {key: _decoded(value) for key, value in record.items()}
            for name, record in summary.metadata.items()
        },
    }


def _fields(values: Any) -> str:
    """``key=value ...``; a nested value as compact JSON."""
    if not isinstance(values, dict):
        return str(values)
    return " ".join(
        f"{k}={v if isinstance(v, str | int | float) else json.dumps(v, separators=(',', ':'))}"
        for k, v in values.items()
    )


def _stack_lines(stack_json: str) -> list[str]:
    """One line per stack config section: ``section: key=value ...``."""
    sections = _decoded(stack_json)
    if not isinstance(sections, dict):
        return [stack_json]
    return [f"{name}: {_fields(values)}" for name, values in sections.items()]


def robot_lines(world: dict[str, str]) -> list[str]:
    """The robot's geometry as recorded, each value with where it came from."""
    if "robot" not in world:
        return []
    robot = _decoded(world["robot"])
    sources = _decoded(world.get("robot_sources", "{}"))
    if not isinstance(robot, dict) or not isinstance(sources, dict):
        return []
    lines = []
    for key in ("wheel_radius", "wheel_separation", "footprint"):
        source = sources.get(key, "")
        lines.append(f"{key}={robot.get(key)}" + (f"  <- {source}" if source else ""))
    for key, source in sources.items():
        if key not in ("wheel_radius", "wheel_separation", "footprint"):
            lines.append(f"{key}: {source}")
    return ["robot:     " + lines[0], *("           " + line for line in lines[1:])]


def info_main(args: argparse.Namespace) -> int:
    from otonav.record._reader import summarize

    summary = summarize(args.file)
    if summary.truncated:
        warn_cut_off(summary, "showing")
    # Exit 1 on damage: the facts shown are not the whole recording.
    code = 1 if warn_damaged(summary, "rates and times are from") else 0
    if args.json:
        print(json.dumps(as_json(summary), indent=2))
        return code

    from rich.table import Table

    from otonav.cli._console import make_console

    console = make_console()
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
    run = summary.metadata.get("otonav", {})
    if "scenario" in run:
        console.print(f"scenario:  {run['scenario']}   seed: {run.get('seed', '-')}")
    if "scenario_config" in run:
        console.print("           " + _fields(_decoded(run["scenario_config"])), soft_wrap=True)
    if "stack_config" in run:
        lines = _stack_lines(run["stack_config"])
        console.print("stack:     " + "\n           ".join(lines), soft_wrap=True)
    world = summary.metadata.get("otonav.world", {})
    for line in robot_lines(world):
        console.print(line, soft_wrap=True)
    if "verdict" in run:
        console.print(f"verdict:   {run['verdict']}", soft_wrap=True)
    elif run:
        console.print("verdict:   - (the run did not finish: no verdict was recorded)")
    return code


def salvage_main(args: argparse.Namespace) -> int:
    from otonav.record._salvage import salvage
    from otonav.record._verify import Damage, describe_damage

    damaged: list[Damage] = []
    count = salvage(args.source, args.target, overwrite=args.force, damaged=damaged)
    print(f"salvaged {count} messages from {args.source} into {args.target}")
    if damaged:  # exit 1: the copy is not all that was recorded
        chunks = sum(1 for d in damaged if d.start_ns is not None)
        print(
            f"otonav: warning: skipped {chunks} damaged chunk{'s' if chunks != 1 else ''} "
            f"(not copied): {describe_damage(args.source, damaged)}",
            file=sys.stderr,
        )
        return 1
    return 0
