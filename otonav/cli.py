"""Command-line interface (grows with the robot issue)."""

from __future__ import annotations


def main(argv: list[str] | None = None) -> int:
    print("otonav: the runtime is installed; the default scenario lands with the robot stack.")
    return 0
