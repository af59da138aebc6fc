"""``otonav run``: run a scenario headless in virtual time, print the verdict."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # the command's imports are in main(): --help stays fast
    from contextlib import ExitStack

    from rich.console import Console

    from otonav.cli._signals import StopOnSignals
    from otonav.engine import Extras
    from otonav.runtime import System
    from otonav.scenario import Verdict

DEFAULT_OUT = Path("out")
BAG_DIR = "bag"
"""``--bag``: the rosbag2 directory inside ``--out``."""


class _HelpFormatter(argparse.HelpFormatter):
    """Fills ``{builtin}`` in a flag's help with the built-in scenario names, only when
    the help is printed (building the parser must not import the scenarios)."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = super()._get_help_string(action)
        if text is not None and "{builtin}" in text:
            from otonav.scenario._builtin import BUILTIN

            text = text.replace("{builtin}", ", ".join(BUILTIN))
        return text


def add_parser(commands: Any) -> None:
    p = commands.add_parser(
        "run",
        help="run a scenario (default: acceptance) headless",
        formatter_class=_HelpFormatter,
    )
    p.add_argument(
        "--scenario",
        default="acceptance",
        metavar="NAME|PATH",
        help="a built-in scenario ({builtin}; 'otonav scenarios' describes them) "
        "or a scenario YAML file (default: acceptance)",
    )
    p.add_argument("--config", type=Path, help="stack config YAML (default: built-in)")
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY.PATH=VALUE",
        help="override a stack config key, e.g. --set nav.kp_lin=0 (repeatable)",
    )
    p.add_argument(
        "--actor",
        dest="actors",
        action="append",
        default=[],
        metavar="MODULE:CLASS",
        help="launch your node too, e.g. --actor my_nodes:Wander (repeatable; named by the "
        "class in snake_case, its parameters set with --set actors.wander.KEY=VALUE)",
    )
    p.add_argument("--seed", type=int, help="override the scenario's seed")
    p.add_argument(
        "--out", type=Path, default=DEFAULT_OUT, help="artifact directory (default: out)"
    )
    p.add_argument("--no-record", action="store_true", help="do not write recording.mcap")
    p.add_argument(
        "-v",
        "--verbose",
        action="store_true",
        help="print every log line (nodes' info and debug, lifecycle events); by default "
        "only warnings and errors",
    )
    p.add_argument(
        "--bag",
        action="store_true",
        help="also make OUT/bag a rosbag2 bag directory (metadata.yaml + the recording) "
        "for ros2 bag and rosbags",
    )
    p.add_argument(
        "--realtime", action="store_true", help="pace sim time to the wall clock (same actors)"
    )
    p.add_argument(
        "--scale",
        type=float,
        default=None,
        help="with --realtime/--gui only: sim seconds per wall second (default 1)",
    )
    p.add_argument(
        "--gui",
        action="store_true",
        help="show the run in MuJoCo's viewer (real time); the camera follows the robot",
    )
    p.add_argument(
        "--hold",
        action="store_true",
        help="with --gui: keep the window open at the end, until you close it",
    )
    live = p.add_argument_group("live view in Foxglove (needs the otonav[foxglove] extra)")
    live.add_argument(
        "--foxglove",
        action="store_true",
        help="serve every topic over the Foxglove WebSocket protocol while the run goes",
    )
    live.add_argument(
        "--foxglove-port",
        type=int,
        default=None,
        metavar="PORT",
        help="TCP port (default: foxglove.port, 8765; 0: any free port)",
    )
    live.add_argument(
        "--foxglove-host",
        default=None,
        metavar="HOST",
        help="interface to bind (default: foxglove.host, 127.0.0.1, loopback only; 0.0.0.0: "
        "every interface)",
    )
    live.add_argument(
        "--foxglove-wait",
        type=float,
        default=None,
        metavar="S",
        help="hold sim time at the start until a client subscribes (at most S wall seconds)",
    )
    ros2 = p.add_argument_group("ROS 2 over DDS (needs the otonav[ros2] extra)")
    ros2.add_argument(
        "--ros2",
        action="store_true",
        help="publish every topic on DDS as a ROS 2 node does (rt/odom ...) and take /goal "
        "in; the run is paced to the wall clock (as --realtime); stays on this host unless "
        "ROS_AUTOMATIC_DISCOVERY_RANGE says otherwise",
    )
    ros2.add_argument(
        "--ros2-domain",
        type=int,
        default=None,
        metavar="N",
        help="DDS domain 0..232 (default: ROS_DOMAIN_ID, else 0)",
    )
    ros2.add_argument(
        "--ros2-in",
        dest="ros2_inputs",
        action="append",
        default=None,
        metavar="TOPIC",
        help="a topic ROS 2 nodes may publish into the stack (repeatable; default /goal; "
        "e.g. /cmd_vel_nav to drive the robot from your own planner)",
    )
    ros2.add_argument(
        "--lockstep",
        nargs="?",
        action="append",
        const="",
        default=None,
        metavar="TOPIC:PERIOD",
        help="run the ROS 2 nodes in otonav's time, as fast as they follow: sim time holds at "
        "each instant an answer is due (a message on TOPIC every PERIOD s of sim time, e.g. "
        "/cmd_vel_nav:0.05; repeatable; default: the config's ros2.lockstep) until it came",
    )
    ros2.add_argument(
        "--ros2-wait",
        type=float,
        default=None,
        metavar="S",
        help="hold sim time at 0 until the ROS 2 nodes matched, at most S wall seconds "
        "(default: no wait; 30 with --lockstep)",
    )
    p.set_defaults(handler=main)


def robot_rows(verdict: Verdict) -> list[tuple[str, str]]:
    """The robot the verdict is about, and the budget it had (scaled to its speed)."""
    robot = verdict.robot
    if not robot:
        return []
    top = f", top {robot['max_v']:g} m/s" if robot.get("max_v") else ""
    return [
        ("robot", f"{robot['model']}{top}"),
        ("wheels", f"r {robot['wheel_radius']:.4f} m, {robot['wheel_separation']:.3f} m apart"),
        *reach_row(robot.get("reach")),
        ("sim budget", f"{verdict.sim_budget_s:g} s"),
    ]


def reach_row(reach: dict[str, float] | None) -> list[tuple[str, str]]:
    """What the robot really reached against what it was asked (ADR 0066)."""
    if not reach:
        return []
    v, asked = reach["v"], reach["asked_v"]
    return [("reaches", f"{v:.3g} of {asked:.3g} m/s asked ({v / asked:.0%})")]


def print_verdict(verdict: Verdict, console: Console) -> None:
    from rich.table import Table

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
        *robot_rows(verdict),
    ):
        table.add_row(key, value)
    console.print(table)
    console.print(f"why: {verdict.reason}")
    for label, path in (("recording", verdict.recording), ("plot", verdict.plot)):
        if path:
            console.print(f"{label}: {path}")


def main(args: argparse.Namespace) -> int:
    import contextlib

    from otonav.cli._signals import StopOnSignals

    with StopOnSignals() as guard, contextlib.ExitStack() as locks:
        return _main(args, guard, locks)


def _main(args: argparse.Namespace, guard: StopOnSignals, locks: ExitStack) -> int:
    import asyncio
    import gc
    import json
    import shutil
    import sys

    from pydantic import ValidationError

    from otonav.cli._console import make_console
    from otonav.cli._loading import load_scenario, load_stack
    from otonav.cli._progress import ProgressLine
    from otonav.limits import check_scale
    from otonav.record._diskfull import DiskFullError, is_disk_full
    from otonav.record._outlock import lock_output
    from otonav.runtime import RealTime, Virtual, WallClockCeilingError
    from otonav.scenario import ScenarioConfig, run_scenario
    from otonav.scenario._builtin import BUILTIN
    from otonav.scenario._crash import RunCrashedError
    from otonav.scenario._verdict import finite_figures
    from otonav.stack._files import ConfigFileError, describe_validation_error

    scale = 1.0 if args.scale is None else args.scale
    if args.scale is not None and not (args.realtime or args.gui or args.ros2):
        raise ConfigFileError(
            f"--scale {args.scale:g}: only with --realtime, --gui or --ros2 "
            "(a headless run is not paced: it runs as fast as it can)"
        )
    if args.bag and args.no_record:
        raise ConfigFileError("--bag: not with --no-record (the bag is the recording)")
    if args.hold and not args.gui:
        raise ConfigFileError("--hold: only with --gui (it keeps the viewer window open)")
    problem = check_scale(scale)
    if problem is not None:
        raise ConfigFileError(problem)
    scenario = load_scenario(args.scenario)
    if args.seed is not None:  # validated like the file (model_copy would not check it)
        try:
            scenario = ScenarioConfig.model_validate({**scenario.model_dump(), "seed": args.seed})
        except ValidationError as exc:
            raise ConfigFileError(describe_validation_error("--seed", exc)) from None
    stack = load_stack(args.config, args.overrides, args.actors)
    out: Path = args.out
    locks.enter_context(lock_output(out))  # one run per --out: a second one is refused
    source = args.scenario if args.scenario not in BUILTIN else f"scenario '{args.scenario}'"
    progress = ProgressLine() if sys.stderr.isatty() else None
    stale = [out / "summary.json"] + ([out / "recording.mcap"] if args.no_record else [])

    def on_start(loop: asyncio.AbstractEventLoop, task: asyncio.Task[None]) -> None:
        # The run has started (its input is valid, its world built, its recording
        # opened): the previous run's artifacts must not pass for this one's. Nothing is
        # deleted on bad input. An interrupted run writes no summary.json.
        for path in stale:
            path.unlink(missing_ok=True)
        # The bag's file is a link to recording.mcap, which this run rewrites.
        shutil.rmtree(out / BAG_DIR, ignore_errors=True)
        guard.attach(loop, task)  # a signal now cancels the run, which then finishes

    stack = _with_flags(args, stack)
    extras = _extras(stack)
    locks.callback(extras.close)
    _announce(args, extras)
    bridge = extras.ros2
    lockstep = bridge is not None and bool(bridge.options.lockstep)
    console = make_console()
    held: list[Verdict] = []

    def hold(verdict: Verdict) -> None:
        print_verdict(verdict, console)
        console.print("the recording is finished; close the viewer window to exit")
        held.append(verdict)

    if args.owns_process:
        # Start-up is done (modules imported, configs read, the live view bound): what
        # exists now lives as long as the process. Out of the cyclic collector's sight it
        # cannot cause a full collection inside the run: 40-80 ms at a process's first
        # run, more than one navigation period of a real-time run (ADR 0063). Not when a
        # host calls main(): objects it holds now would never be collected later.
        gc.collect()
        gc.freeze()
    guard.arm()  # from here a signal stops the run and lets it finish its artifacts
    try:
        paced = args.gui or args.realtime or (bridge is not None and not lockstep)
        verdict = run_scenario(
            scenario,
            stack,
            out_dir=out,
            record=not args.no_record,
            # the progress line is for virtual time; a paced run is watched as it goes
            progress=None if paced else progress,
            source=source,
            on_start=on_start,
            extra_actors=extras.actors,
            time=RealTime(scale) if paced else Virtual(),
            gui=args.gui,
            hold=hold if paced and args.hold else None,
            on_system=lambda system: _serve_parameters(extras, system),
        )
    except RunCrashedError as crash:
        # An actor crashed (one line on stderr from the log; the traceback is on
        # /rosout): a failed run with its verdict and artifacts, not a raw traceback.
        verdict = crash.verdict
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
        extras.close()
    if guard.received is not None:  # the run had ended; the signal came while saving
        return guard.report()
    out.mkdir(parents=True, exist_ok=True)
    if args.bag and verdict.recording:
        from otonav.record._bag import write_bag_directory

        console.print(f"bag: {write_bag_directory(Path(verdict.recording), out / BAG_DIR)}")
    summary = out / "summary.json"
    try:
        summary.write_text(
            json.dumps(finite_figures(verdict.as_dict()), indent=2, default=str) + "\n"
        )
    except OSError as exc:
        if not is_disk_full(exc):
            raise
        summary.unlink(missing_ok=True)  # half a summary would pass for one
        raise DiskFullError(
            summary, exc, "the recording and plot were written; the summary was not"
        ) from exc
    if held:  # the table was printed while the window was held open
        for label, path in (("recording", verdict.recording), ("plot", verdict.plot)):
            if path:
                console.print(f"{label}: {path}")
    else:
        print_verdict(verdict, console)
    console.print(f"summary: {summary}")
    return 0 if verdict.passed else 1


def _extras(stack: Any) -> Extras:
    """The Foxglove view and the ROS 2 bridge the config enables (one line, exit 2, when
    one cannot start): made in one place for every entry point (otonav.engine)."""
    from otonav.engine import ExtrasError, open_extras
    from otonav.stack._files import ConfigFileError

    try:
        return open_extras(stack)
    except ExtrasError as exc:
        raise ConfigFileError(str(exc)) from None


_SECTION_FLAGS = {
    "--foxglove-host": ("foxglove", "host", "foxglove_host"),
    "--foxglove-port": ("foxglove", "port", "foxglove_port"),
    "--foxglove-wait": ("foxglove", "wait_for_subscriber", "foxglove_wait"),
    "--ros2-domain": ("ros2", "domain_id", "ros2_domain"),
    "--ros2-in": ("ros2", "inputs", "ros2_inputs"),
    "--lockstep": ("ros2", "lockstep", "lockstep"),
    "--ros2-wait": ("ros2", "wait", "ros2_wait"),
}
"""Each ``--foxglove-*``/``--ros2*`` flag: the config section and field it sets, and its
argument's dest."""


def _with_flags(args: argparse.Namespace, stack: Any) -> Any:
    """The stack config with the ``--foxglove*`` and ``--ros2*`` flags applied to its
    ``foxglove`` and ``ros2`` sections, checked as the config is (one line naming the
    flag and what is valid)."""
    from pydantic import ValidationError

    from otonav.stack._files import ConfigFileError, describe_validation_error

    update: dict[str, Any] = {}
    for name in ("foxglove", "ros2"):
        section = getattr(stack, name)
        given = {
            flag: getattr(args, dest)
            for flag, (owner, _field, dest) in _SECTION_FLAGS.items()
            if owner == name and getattr(args, dest) not in (None, [])
        }
        if not (getattr(args, name) or section.enabled):
            if given:
                raise ConfigFileError(f"{'/'.join(given)}: only with --{name} (or {name}.enabled)")
            continue
        if name == "foxglove" and not (given or args.foxglove):
            continue
        fields = {_SECTION_FLAGS[flag][1]: value for flag, value in given.items()}
        if name == "ros2":
            fields = _ros2_fields(args, section, fields)
        try:
            update[name] = type(section).model_validate(
                {**section.model_dump(), **fields, "enabled": True}
            )
        except ValidationError as exc:
            field = str(exc.errors()[0]["loc"][0]) if exc.errors() else ""
            flags = [flag for flag, (o, f, _d) in _SECTION_FLAGS.items() if (o, f) == (name, field)]
            flag = flags[0] if flags and field in fields else f"{name}.{field}"
            raise ConfigFileError(describe_validation_error(flag, exc)) from None
    return stack.model_copy(update=update) if update else stack


def _announce(args: argparse.Namespace, extras: Extras) -> None:
    """Say on stderr where the live view and the bridge serve, before the run starts."""
    import sys

    server = extras.foxglove
    if server is not None:
        hint = ""
        if not (args.realtime or args.gui) and server.config.wait_for_subscriber is None:
            hint = (
                "; in virtual time the run may be over before a client connects: --foxglove-wait S"
            )
        print(
            f"foxglove: serving every topic on {server.url} (Foxglove: Open connection -> "
            f"Foxglove WebSocket){hint}",
            file=sys.stderr,
            flush=True,
        )
    bridge = extras.ros2
    if bridge is not None:
        options = bridge.options
        if options.lockstep:
            answers = ", ".join(f"{a.topic} every {a.period:g} s" for a in options.lockstep)
            timing = f"in lockstep: sim time waits for {answers}"
        else:
            timing = "paced to the wall clock"
        print(
            f"ros2: every topic on DDS domain {bridge.domain_id} (rt/odom ...), seen from "
            f"{bridge.discovery.scope}; taking {', '.join(options.inputs)} in; {timing}",
            file=sys.stderr,
            flush=True,
        )


def _serve_parameters(extras: Extras, system: System) -> None:
    """What ``run_scenario`` calls with the run's system: the extras serve the parameters
    of every actor of it (Foxglove's Parameters panel, as ros-foxglove-bridge serves a
    robot's nodes', docs/adr/0044; ROS 2 parameter services, 0065), and the command says
    which ones Foxglove can set."""
    import sys

    table = extras.serve_parameters(system)
    if table is None:
        return
    names = list(table.values())
    settable = sorted({n.split(".")[0] for n in names if table.settable(n)})
    fields = ", ".join(f"{actor}.params.FIELD" for actor in settable) or "none"
    print(
        f"foxglove: serving the parameters of the run's actors ({len(names)}; "
        f"Foxglove: Parameters panel); numbers settable while it runs: {fields}",
        file=sys.stderr,
        flush=True,
    )


def _ros2_fields(args: argparse.Namespace, section: Any, fields: dict[str, Any]) -> dict[str, Any]:
    """The ``ros2`` fields the flags set, as the section takes them: ``--lockstep``'s
    TOPIC:PERIOD parsed, the domain and the inputs checked by the bridge's own rules, and
    in lockstep a wait for the nodes (not with a paced run)."""
    from otonav.ros2._naming import Ros2Error, dds_topic, domain_id
    from otonav.stack._files import ConfigFileError

    given = [value for value in fields.pop("lockstep", ()) if value]
    answers = []
    for value in given:
        topic, _, period = value.rpartition(":")
        try:
            answers.append({"topic": topic, "period": float(period)})
        except ValueError:
            raise ConfigFileError(
                f"--lockstep {value}: expected TOPIC:PERIOD, e.g. /cmd_vel_nav:0.05"
            ) from None
    if answers:
        fields["lockstep"] = tuple(answers)
    if "inputs" in fields:
        fields["inputs"] = tuple(fields["inputs"])
    if args.lockstep is not None and not given and not section.lockstep:
        raise ConfigFileError(
            "--lockstep: say what your nodes answer with, e.g. --lockstep /cmd_vel_nav:0.05 "
            "(or ros2.lockstep in the stack config)"
        )
    try:  # the flags' own one-line messages (the bridge's checks)
        if "domain_id" in fields:
            fields["domain_id"] = domain_id(fields["domain_id"], {})
        for topic in fields.get("inputs", ()):
            dds_topic(topic)
    except Ros2Error as exc:
        prefix = "" if str(exc).startswith("--") else "--ros2-in "
        raise ConfigFileError(prefix + str(exc)) from None
    lockstep = fields.get("lockstep", section.lockstep)
    if lockstep and (args.realtime or args.gui or args.scale is not None):
        raise ConfigFileError(
            "--lockstep: not with --realtime, --gui or --scale (sim time follows the nodes)"
        )
    if lockstep and fields.get("wait", section.wait) is None:
        fields["wait"] = 30.0  # a node started a moment later must not miss the start
    return fields
