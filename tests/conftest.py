"""Test-suite configuration: pytester for testing the otonav pytest plugin itself, and the
one check every bad-input test makes (`cli_fails`)."""

from __future__ import annotations

from collections.abc import Callable

import pytest

pytest_plugins = ["pytester"]

CliFails = Callable[..., str]
"""``cli_fails(argv, *fragments) -> the error line``."""


@pytest.fixture
def cli_fails(capsys: pytest.CaptureFixture[str]) -> CliFails:
    """Run ``otonav`` with ``argv`` and check it refused as a user's mistake must be refused:
    exit 2, one short line on stderr that starts ``otonav: error:`` and holds every
    fragment (the file or key and what is valid), no traceback. Returns the line."""
    from otonav.cli import main

    def fails(argv: list[str], *fragments: str) -> str:
        code = main(argv)
        err = capsys.readouterr().err
        assert code == 2, err
        assert "Traceback" not in err
        lines = err.strip().splitlines()
        assert len(lines) == 1, err
        line = lines[0]
        assert line.startswith("otonav: error: "), line
        assert len(line) < 600, line[:600]
        for fragment in fragments:
            assert fragment in line, line
        return line

    return fails
