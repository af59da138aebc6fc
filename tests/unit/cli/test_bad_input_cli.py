"""Bad input at the CLI that used to be accepted: a start or goal hugging a wall, an
"MCAP" that is only the magic, configuration files that cost too much to read (issue
17, items 3 and 5). One line, exit 2, nothing run."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from otonav.record._reader import MAGIC

pytestmark = pytest.mark.unit


@pytest.mark.parametrize(
    ("text", "key"),
    [
        ("start: {x: 4.8, y: 0.0}\n", "start"),  # 0.2 m from the wall face at x = 5
        ("goal: {x: 0.0, y: -4.9}\n", "goal"),  # 0.1 m from the wall face at y = -5
        ("scene: empty\ngoal: {x: 4.75, y: 4.75}\n", "goal"),  # a corner of the empty arena
    ],
)
def test_start_or_goal_too_close_to_a_wall(
    cli_fails: Callable[..., str], tmp_path: Path, text: str, key: str
) -> None:
    f = tmp_path / "s.yaml"
    f.write_text(text)
    cli_fails(
        ["run", "--scenario", str(f), "--out", str(tmp_path)],
        str(f),
        f"{key}:",
        "from the wall",
        "min_clearance = 0.3",
    )
    assert not (tmp_path / "recording.mcap").exists()


def test_info_on_the_magic_and_garbage_is_exit_2(
    cli_fails: Callable[..., str], tmp_path: Path
) -> None:
    f = tmp_path / "junk.mcap"
    f.write_bytes(MAGIC + b"\x00garbage that is no record" * 40)
    cli_fails(["info", str(f)], str(f), "no readable MCAP header")


def _bomb(levels: int) -> str:
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x]"]
    for i in range(1, levels):
        lines.append(f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]")
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(
    ("content", "fragments"),
    [
        # 9^7 = 4.8 million strings from 600 bytes (the full bomb: 2.7 GB, no output).
        (_bomb(7).encode(), ("expands to more than 100,000 values",)),
        (b"a: &a [*a]\n", ("recursive alias",)),
        (b"a: " + b"[" * 5000 + b"]" * 5000 + b"\n", ("nested deeper than 32 levels",)),
        (
            "world:\n  scene: 'caf\u00e9'\n".encode("latin-1"),
            ("not UTF-8", "byte 0xe9 at offset 20"),
        ),
        (b"\xff\xfeworld: {}\n", ("not UTF-8", "offset 0")),
        (b"# " + b"x" * ((1 << 20) + 1) + b"\n", ("larger than 1024 KiB",)),
        (b"world:\n  scene: '" + b"s" * 10_000_000 + b"'\n", ("larger than 1024 KiB",)),
    ],
    ids=["anchor-bomb", "recursive-alias", "deep", "latin-1", "utf-16", "big", "10MB-name"],
)
def test_config_files_over_a_limit(
    cli_fails: Callable[..., str],
    tmp_path: Path,
    content: bytes,
    fragments: tuple[str, ...],
) -> None:
    f = tmp_path / "stack.yaml"
    f.write_bytes(content)
    cli_fails(["run", "--config", str(f), "--out", str(tmp_path)], str(f), *fragments)
    cli_fails(["run", "--scenario", str(f), "--out", str(tmp_path)], str(f), *fragments)


def test_set_values_are_parsed_within_the_same_limits(
    cli_fails: Callable[..., str],
) -> None:
    bomb = _bomb(7).replace("\n", ", ").replace("a0: ", "{a0: ", 1).rstrip(", ") + "}"
    cli_fails(["run", "--set", f"world.scene={bomb}"], "--set world.scene", "expands")


def test_long_names_through_set_are_refused_in_a_short_line(
    cli_fails: Callable[..., str],
) -> None:
    cli_fails(["run", "--set", "world.scene=" + "s" * 5000], "world.scene", "4096")
    cli_fails(["run", "--set", "world.scene=" + "s" * 10_000_000], "world.scene", "KiB")


def test_anchors_for_ordinary_reuse_still_work(tmp_path: Path) -> None:
    from otonav.scenario import ScenarioConfig
    from otonav.stack._files import load_model

    f = tmp_path / "s.yaml"
    f.write_text(
        "obstacles:\n"
        "  - &box {x: 1.0, y: 1.0, size_x: 0.2, size_y: 0.2}\n"
        "  - *box\n"
        "sim_budget: 1e1\n"  # a YAML 1.2 float
    )
    scenario = load_model(f, ScenarioConfig)
    assert scenario.obstacles[0] == scenario.obstacles[1]
    assert scenario.sim_budget == 10.0


def test_sweep_set_values_are_parsed_within_the_same_limits(
    cli_fails: Callable[..., str], tmp_path: Path
) -> None:
    # A grid value is parsed as YAML too: 3000 levels were a RecursionError traceback.
    deep = "[" * 3000 + "]" * 3000
    argv = ["sweep", "--scenario", "acceptance", "--set", f"nav.kp_lin={deep}"]
    cli_fails([*argv, "--out", str(tmp_path)], "nav.kp_lin", "nested deeper than 32")
