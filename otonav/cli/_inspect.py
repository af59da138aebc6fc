"""``otonav graph``, ``otonav scenarios`` and ``otonav plot``."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any


def add_parser(commands: Any) -> None:
    g = commands.add_parser("graph", help="actors, topics, types and QoS of the configured stack")
    g.add_argument("--config", type=Path, help="stack config YAML (default: built-in)")
    g.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE")
    g.add_argument("--actor", dest="actors", action="append", default=[], metavar="MODULE:CLASS")
    g.set_defaults(handler=graph_main)
    s = commands.add_parser("scenarios", help="list the built-in scenarios")
    s.set_defaults(handler=scenarios_main)
    p = commands.add_parser("plot", help="draw the path recorded in an MCAP file as a PNG")
    p.add_argument("file", type=Path)
    p.add_argument(
        "--out",
        type=Path,
        help="PNG path, or a directory to write FILE.png in (default: next to the file)",
    )
    p.set_defaults(handler=plot_main)


def graph_main(args: argparse.Namespace) -> int:
    from rich.table import Table

    from otonav.cli._console import make_console
    from otonav.cli._loading import load_stack
    from otonav.runtime import System
    from otonav.stack import build_actors, build_world
    from otonav.stack._rosout import attach_rosout

    stack = load_stack(args.config, args.overrides, args.actors)
    hal = build_world(stack)
    try:
        built = build_actors(stack, hal)
        system = System(built)
        attach_rosout(system)
        graph = system.graph()
    finally:
        hal.close()
    console = make_console(width=140)
    actors = Table(title="actors")
    for column in ("actor", "kind", "subscribes", "publishes", "parameters"):
        actors.add_column(column)
    params = {actor.name: parameter_lines(actor.name, actor.parameters) for actor in built}
    for a in graph.actors:
        actors.add_row(
            a.name, a.kind, "\n".join(a.inputs), "\n".join(a.outputs), params.get(a.name, "")
        )
    console.print(actors)
    topics = Table(title="topics (a recording adds the recorder on every topic)")
    for column in ("topic", "type (ROS 2)", "publishers (QoS)", "subscribers (QoS)"):
        topics.add_column(column)
    for t in graph.topics:
        topics.add_row(
            t.name,
            t.ros_type or t.type.rsplit(".", 1)[-1],
            "\n".join(f"{p.actor} ({p.qos})" for p in t.publishers),
            "\n".join(f"{s.actor} ({s.qos})" for s in t.subscriptions),
        )
    console.print(topics)
    return 0


BUILTIN_SECTIONS = {
    "bridge": "rates.*, world.lidar_*",
    "base": "base.*",
    "nav": "nav.*",
    "safety": "safety.*",
}
"""Where the built-in actors' parameters live in the stack config."""


def parameter_lines(name: str, parameters: Any) -> str:
    """A launched actor's parameters as ``key=value`` lines (``--set actors.NAME.KEY``),
    or the config section of a built-in one."""
    if parameters:
        return "\n".join(f"{key}={value}" for key, value in parameters.items())
    return BUILTIN_SECTIONS.get(name, "")


def scenarios_main(_args: argparse.Namespace) -> int:
    from rich.table import Table

    from otonav.cli._console import make_console
    from otonav.scenario._builtin import BUILTIN, describe

    table = Table(title="built-in scenarios (run one: otonav run --scenario NAME)")
    table.add_column("name")
    table.add_column("what")
    for name in BUILTIN:
        table.add_row(name, describe(name))
    make_console().print(table)
    return 0


def plot_main(args: argparse.Namespace) -> int:
    from otonav.cli._info import warn_cut_off, warn_damaged
    from otonav.record._reader import summarize
    from otonav.scenario._replay import plot_recording

    out = plot_target(args.file, args.out)
    summary = summarize(args.file)
    if summary.truncated:
        warn_cut_off(summary, "drawing")
    damaged = warn_damaged(summary, "drawing")
    png = plot_recording(args.file, out)
    print(f"plot: {png}")
    return 1 if damaged else 0  # the plot is not all that was recorded


def plot_target(recording: Path, out: Path | None) -> Path | None:
    """Where ``plot --out`` writes: a directory gets ``<recording stem>.png`` inside it
    (``--out /tmp`` wrote ``/tmp.png``, issue 27); a file must be a ``.png``."""
    from otonav.stack._files import ConfigFileError

    if out is None:
        return None
    if out.is_dir() or str(out).endswith(("/", "\\")):
        return out / f"{recording.stem}.png"
    if out.suffix.lower() != ".png":
        raise ConfigFileError(
            f"--out {out}: a plot is a PNG: give a path ending in .png, or a directory"
        )
    return out
