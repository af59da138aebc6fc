"""``python -m otonav`` / ``otonav``: run scenarios, inspect recordings.

Adding a command: write ``otonav/cli/NAME.py`` with ``add_parser(commands)`` (which calls
``commands.add_parser(...)`` and ``set_defaults(handler=main)``) and a ``main(args) -> int``;
then add ``"NAME"`` to :data:`COMMANDS`. A command module's top level imports the standard
library only: every command's parser is built for every invocation (``otonav --help``
lists them all), so the stack, MuJoCo, matplotlib, numpy, Ray etc. are imported inside
``main``. ``tests/unit/cli/test_cli_imports.py`` fails when one leaks (``--help`` took
1.0-1.4 s when they did; now ~0.1 s).
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from otonav.errors import UsageError
from otonav.record import _diskfull as _diskfull

if TYPE_CHECKING:
    from otonav.cli._loading import load_scenario, load_stack

__all__ = ("build_parser", "load_scenario", "load_stack", "main")
"""The command line is the CLI's interface; from Python: :func:`main` (``argv`` as
typed), :func:`build_parser` (the docs' CLI reference is generated from it), and the
loaders a host uses to take configs as ``otonav run`` does (imported on first use, like
every command's dependencies)."""

COMMANDS: tuple[str, ...] = (
    "run",
    "info",
    "echo",
    "inspect",
    "bench",
    "sweep",
    "replay",
    "play",
)
"""Modules under ``otonav.cli`` whose ``add_parser`` registers a command, in help order."""

USAGE_ERROR = 2


EPILOG = """\
With no command, otonav runs `run` with its defaults (the acceptance scenario);
a leading option goes to `run` too: `otonav --set nav.kp_lin=0`.

exit codes:
  0        the scenario passed, or the command succeeded
  1        the scenario failed
  2        usage or configuration error (one line on stderr, no traceback)
  4        the disk is full (or a quota or file size limit): the run was stopped,
           what was written is kept; one line names the file and the way on
           (`otonav salvage` for a recording)
  130/143  interrupted by Ctrl-C / SIGTERM (the recording is finished and readable)
"""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        print(f"{self.prog}: error: {message}", file=sys.stderr)
        raise SystemExit(USAGE_ERROR)


class _VersionAction(argparse.Action):
    """``--version``: the code's version (``otonav/_version.py``, the one pyproject.toml
    and recordings carry)."""

    def __init__(self, option_strings: Sequence[str], dest: str, **kwargs: Any) -> None:
        kwargs.update(nargs=0, default=argparse.SUPPRESS)
        super().__init__(option_strings, argparse.SUPPRESS, **kwargs)

    def __call__(self, parser: argparse.ArgumentParser, *_args: object, **_kw: object) -> None:
        from otonav._version import __version__

        print(f"otonav {__version__}")
        parser.exit()


def build_parser() -> argparse.ArgumentParser:
    """The ``otonav`` command line: every subcommand and its options."""
    parser = _Parser(
        prog="otonav",
        description="Deterministic robot scenarios in sim time.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action=_VersionAction, help="print the version and exit")
    commands = parser.add_subparsers(dest="command", parser_class=_Parser, metavar="COMMAND")
    for name in COMMANDS:
        importlib.import_module(f"otonav.cli._{name}").add_parser(commands)
    return parser


def main(argv: Sequence[str] | None = None, *, owns_process: bool = False) -> int:
    """Run the command line ``argv`` (``sys.argv[1:]`` if None); the exit code.

    ``owns_process``: the CLI is this process (the ``otonav`` script, ``python -m
    otonav``), so ``otonav run`` may freeze what start-up made out of the cyclic
    collector's sight (ADR 0063). A host calling ``main`` leaves it False: freezing is
    the host's process-wide choice."""
    args_list = list(sys.argv[1:] if argv is None else argv)
    if not args_list or (
        args_list[0].startswith("-") and args_list[0] not in ("-h", "--help", "--version")
    ):
        args_list = ["run", *args_list]  # no command = run the default scenario
    args = build_parser().parse_args(args_list)
    args.owns_process = owns_process
    from otonav.cli import _logs as logs

    logs.install(verbose=getattr(args, "verbose", False))
    try:
        code: int = args.handler(args)
        return code
    except KeyboardInterrupt:
        print("otonav: interrupted; the recording was finished and is readable", file=sys.stderr)
        return 130
    except Exception as exc:
        if isinstance(exc, _diskfull.DiskFullError) or _diskfull.is_disk_full(exc):
            print(f"otonav: error: {_disk_full_line(exc)}", file=sys.stderr)
            return _diskfull.DISK_FULL_EXIT
        if isinstance(exc, UsageError):  # bad input: every kind derives from it
            print(f"otonav: error: {exc}", file=sys.stderr)
            return USAGE_ERROR
        if isinstance(exc, OSError):  # an unwritable --out, a directory given as a file
            where = f"{exc.filename}: " if exc.filename else ""
            print(f"otonav: error: {where}{exc.strerror or exc}", file=sys.stderr)
            return USAGE_ERROR
        raise


def _disk_full_line(exc: BaseException) -> str:
    """One line for a full disk: the error's own, or the path and the system's words."""
    if isinstance(exc, OSError):
        where = f"{exc.filename}: " if exc.filename else ""
        return f"{where}{(exc.strerror or str(exc)).lower()}"
    return str(exc)


def __getattr__(name: str) -> object:
    if name in ("load_scenario", "load_stack"):
        return getattr(importlib.import_module("otonav.cli._loading"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
