"""Layer 0: repository hygiene that no linter checks."""

from __future__ import annotations

import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
ONE_MB = 1024 * 1024


def _tracked_files() -> list[Path]:
    out = subprocess.run(
        ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True
    ).stdout.decode()
    return [ROOT / name for name in out.split("\0") if name]


def test_no_tracked_file_over_one_megabyte() -> None:
    big = [
        f"{p.relative_to(ROOT)} ({p.stat().st_size} bytes)"
        for p in _tracked_files()
        if p.is_file() and p.stat().st_size > ONE_MB
    ]
    assert not big, f"tracked files over 1 MB (keep artifacts out of git): {big}"


def test_readme_shows_the_two_commands_first() -> None:
    text = (ROOT / "README.md").read_text()
    first_block = text[: text.find("```", text.find("```") + 3)]
    assert "make run" in first_block
    assert "make test" in first_block
