"""``otonav echo TOPIC [RECORDING]``: a recorded topic as YAML, the way ``ros2 topic echo``
prints one (``--once``, ``--field``, a sim-time range). ADR 0070."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Iterable
from pathlib import Path
from typing import Any

DEFAULT_RECORDING = Path("out") / "recording.mcap"


def add_parser(commands: Any) -> None:
    p = commands.add_parser(
        "echo",
        help="print a recorded topic's messages as YAML (like ros2 topic echo), e.g. "
        "otonav echo /rosout",
    )
    p.add_argument("topic", help="the topic, e.g. /rosout or /odom")
    p.add_argument(
        "recording",
        nargs="?",
        type=Path,
        default=DEFAULT_RECORDING,
        help=f"the MCAP file (default: {DEFAULT_RECORDING}, what otonav run writes)",
    )
    p.add_argument("--once", action="store_true", help="print the first message and stop")
    p.add_argument(
        "--field", metavar="PATH", help="print only this field, e.g. msg or pose.pose.position"
    )
    p.add_argument("--since", type=float, metavar="SECONDS", help="from this sim time on")
    p.add_argument("--until", type=float, metavar="SECONDS", help="before this sim time")
    p.set_defaults(handler=main)


def plain(value: Any) -> Any:
    """A message as YAML-ready data: fields in their order, arrays as lists."""
    fields = getattr(type(value), "model_fields", None)
    if fields is not None:
        return {name: plain(getattr(value, name)) for name in fields}
    if isinstance(value, list | tuple):
        return [plain(item) for item in value]
    return value


def field_of(message: Any, path: str) -> Any:
    """``message``'s field at the dotted ``path``; UsageError naming what is there."""
    from otonav.errors import UsageError

    value = message
    for part in path.split("."):
        fields = getattr(type(value), "model_fields", {})
        if part not in fields:
            there = ", ".join(fields) or "none, it is a value"
            raise UsageError(f"--field {path}: no field {part!r} (fields there: {there})")
        value = getattr(value, part)
    return value


def main(args: argparse.Namespace) -> int:
    from otonav.errors import UsageError
    from otonav.record._reader import read_messages, summarize

    topics = [t.topic for t in summarize(args.recording).topics]
    if args.topic not in topics and f"/{args.topic}" in topics:  # ROS 2 resolves it so
        args.topic = f"/{args.topic}"
    if args.topic not in topics:
        raise UsageError(
            f"{args.recording}: no topic {args.topic!r} (topics: {', '.join(sorted(topics))})"
        )
    messages = read_messages(args.recording, [args.topic], start=args.since, end=args.until)
    try:
        _echo(messages, args.field, once=args.once)
    except BrokenPipeError:  # `otonav echo ... | head`: the reader has what it wanted
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # Python's recipe
    return 0


def _echo(messages: Iterable[tuple[str, float, Any]], field: str | None, *, once: bool) -> None:
    import yaml

    for _topic, _time, message in messages:
        value = plain(message if field is None else field_of(message, field))
        if isinstance(value, dict | list):
            text = yaml.safe_dump(value, sort_keys=False, default_flow_style=False)
        else:
            text = yaml.safe_dump(value, default_style=None).removesuffix("...\n")
        sys.stdout.write(f"{text.rstrip()}\n---\n")
        if once:
            break
