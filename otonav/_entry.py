"""The ``otonav`` console script and ``python -m otonav``: the CLI, imported here so
that a Ctrl-C while it is still importing is one line and exit 130, not a traceback."""

from __future__ import annotations

import sys

INTERRUPTED = 130


def main() -> int:
    try:
        from otonav.cli import main as cli_main
    except KeyboardInterrupt:
        print("otonav: interrupted", file=sys.stderr)
        return INTERRUPTED
    try:
        return cli_main(owns_process=True)
    except KeyboardInterrupt:  # outside the CLI's own handling (argument parsing, ...)
        print("otonav: interrupted", file=sys.stderr)
        return INTERRUPTED
