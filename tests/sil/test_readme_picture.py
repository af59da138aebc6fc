"""The README's and the front page's picture is what the default run draws now (issue 39
item 12: it was an older drawing). ``make docs`` puts the build's own run's plot there
(``scripts/docs_hooks.py``); a change to the plot without it fails here."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.cli import main

pytestmark = pytest.mark.sil

PICTURE = Path(__file__).resolve().parents[2] / "docs" / "images" / "trajectory.png"


@pytest.mark.timeout(120)
def test_the_readme_picture_is_the_default_runs_plot(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["run"]) == 0  # as the README says: `otonav run` draws out/trajectory.png
    capsys.readouterr()
    drawn = (tmp_path / "out" / "trajectory.png").read_bytes()
    assert drawn == PICTURE.read_bytes(), "run `make docs` to redraw docs/images/trajectory.png"
