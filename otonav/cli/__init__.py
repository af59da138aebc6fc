"""``python -m otonav`` / ``otonav``: run scenarios, inspect recordings.

Exit codes: 0 scenario passed (or command succeeded), 1 scenario failed,
2 usage or configuration error (one line, no traceback), 130/143 interrupted.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from otonav.cli import bench, info, inspect, run, sweep
from otonav.hal.mujoco import SceneError
from otonav.hal.viewer import NoDisplayError
from otonav.record.reader import RecordingError
from otonav.stack.files import ConfigFileError

USAGE_ERROR = 2


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # type: ignore[override]
        self.print_usage(sys.stderr)
        print(f"{self.prog}: error: {message}", file=sys.stderr)
        raise SystemExit(USAGE_ERROR)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="otonav", description="Deterministic robot scenarios in sim time.")
    commands = parser.add_subparsers(dest="command", parser_class=_Parser)
    run.add_parser(commands)
    info.add_parsers(commands)
    inspect.add_parsers(commands)
    bench.add_parser(commands)
    sweep.add_parser(commands)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args_list = list(sys.argv[1:] if argv is None else argv)
    if not args_list or (args_list[0].startswith("-") and args_list[0] not in ("-h", "--help")):
        args_list = ["run", *args_list]  # no command = run the default scenario
    args = build_parser().parse_args(args_list)
    try:
        code: int = args.handler(args)
        return code
    except (ConfigFileError, RecordingError, SceneError, NoDisplayError) as exc:
        print(f"otonav: error: {exc}", file=sys.stderr)
        return USAGE_ERROR
    except OSError as exc:  # an unwritable --out, a directory given as a file, ...
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"otonav: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return USAGE_ERROR
    except KeyboardInterrupt:
        print("otonav: interrupted; the recording was finished and is readable", file=sys.stderr)
        return 130
