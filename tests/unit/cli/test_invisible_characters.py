"""Names print as what they are: bidi overrides (U+202E), zero-width and other invisible
characters are refused in a scenario's name and an actor's, in one line (issue 27)."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.cli import main

RLO = "\u202e"  # RIGHT-TO-LEFT OVERRIDE: "evil\u202egnp.exe" shows as "evilexe.png"


@pytest.mark.parametrize(
    "name", [f"evil{RLO}gnp", "zero\u200bwidth", "bell\x07", "private\ue000use"]
)
def test_a_scenario_named_with_an_invisible_character_is_refused(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scenario = tmp_path / "s.yaml"
    scenario.write_text(f'name: "{name.encode("unicode_escape").decode()}"\n', encoding="utf-8")
    assert main(["run", "--scenario", str(scenario), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "must be one line of printable text" in err
    assert err.count("\n") == 1


def test_an_actor_named_with_a_bidi_override_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    config = tmp_path / "stack.yaml"
    config.write_text('actors:\n  - {name: "nav\\u202eyl", class: "m:A"}\n', encoding="utf-8")
    assert main(["run", "--config", str(config), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "actors.0.name" in err
    assert "U+202E" in err


def test_ordinary_unicode_names_are_fine(tmp_path: Path) -> None:
    from otonav.limits import one_printable_line

    assert one_printable_line("Überfahrt, 走廊 Ωmega") == "Überfahrt, 走廊 Ωmega"
