"""Layer 0: the docs cannot drift from the code.

The site builds with ``mkdocs build --strict`` (a broken link, a missing page or a generator
that fails is red); the generated reference covers every key and command; every ``otonav``
command line shown in the docs and the README parses with the real argument parser; every
YAML block validates as the file it claims to be. The Python blocks run in
``tests/smoke/test_docs_examples.py``.
"""

from __future__ import annotations

import json
import shlex
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

import docs_hooks  # noqa: E402

from otonav.cli import build_parser  # noqa: E402
from otonav.scenario import ScenarioConfig  # noqa: E402
from otonav.stack import StackConfig  # noqa: E402
from otonav.sweep._spec import SweepSpec  # noqa: E402


def test_the_site_builds_strict(tmp_path: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env={"NO_MKDOCS_2_WARNING": "1", "PATH": str(Path(sys.executable).parent)},
        check=False,
    )
    assert done.returncode == 0, done.stderr[-4000:]
    front = (tmp_path / "index.html").read_text()
    assert "otonav is a robotics stack in pure Python" in front
    config = (tmp_path / "reference" / "config.html").read_text()
    assert "<!-- generated:" not in config
    assert "nav.dwa.horizon" in config
    api = (tmp_path / "reference" / "api" / "testing.html").read_text()
    assert "running_stack" in api


def _leaf_keys(value: Any, prefix: str = "") -> set[str]:
    if isinstance(value, dict) and value:
        return {k for key, sub in value.items() for k in _leaf_keys(sub, f"{prefix}{key}.")}
    return {prefix.rstrip(".")}


def test_the_config_reference_lists_every_key_with_its_default() -> None:
    rows = {row.key: row for row in docs_hooks.config_rows(StackConfig, StackConfig())}
    every = _leaf_keys(StackConfig().model_dump(exclude={"robot"})) | _leaf_keys(
        StackConfig().robot.model_dump(), "robot."
    )
    assert every <= rows.keys(), every - rows.keys()
    assert rows["hal.can.left.sign"].default == "`-1`"  # the section's default, not the class's
    assert rows["world.timestep"].bounds == "[0.0001, 0.01]"
    assert rows["hal.can.encoder_period"].bounds == "[0.001, 1]"  # an AfterValidator's range
    assert rows["actors[].name"].default == "required"
    assert rows["actors[].class"].default != "required"  # none: the built-in of that name


def test_every_physical_quantity_in_the_config_has_a_unit() -> None:
    """A float key is a physical quantity unless it is one of these dimensionless kinds."""
    dimensionless = ("w_", "kp_", "max_frame_loss", "gear_ratio", "plan_penalty", "seed")
    probabilities = {"hal.sim.faults.drop.rate"}  # a fraction of frames, in [0, 1]
    missing = [
        row.key
        for row in docs_hooks.config_rows(StackConfig, StackConfig())
        if row.type.startswith("float")
        and not row.unit
        and row.key not in probabilities
        and not any(part in row.key.rsplit(".", 1)[-1] for part in dimensionless)
    ]
    assert not missing, f"say the unit in the field's docstring (first words): {missing}"


def test_the_cli_reference_has_every_command() -> None:
    text = docs_hooks.cli_reference()
    for name in ("run", "info", "replay", "sweep", "graph", "scenarios", "salvage", "plot"):
        assert f"## `otonav {name}`" in text
    assert "--set KEY.PATH=VALUE" in text


def test_exit_codes_come_from_the_cli() -> None:
    table = docs_hooks.exit_codes()
    for code in ("`0`", "`1`", "`2`", "`130/143`"):
        assert f"| {code} |" in table


def test_volatile_figures_are_masked_and_nothing_else() -> None:
    verdict = "│ wall time        │   0.389 s │\n│ min clearance    │   0.490 m │"
    masked = docs_hooks.mask(verdict)
    assert "0.389" not in masked
    assert "0.490 m" in masked
    assert len(masked) == len(verdict)  # the table keeps its columns
    line = "replayed nav: 13.330 s of sim time in 0.186 s (72x; CPU 0.088 s); fed /goal 1"
    assert docs_hooks.mask(line) == line.replace("0.186 s (72x; CPU 0.088 s)", "…".rjust(26))


def test_an_unknown_generated_block_fails_the_build() -> None:
    with pytest.raises(ValueError, match="unknown generated block 'nope'"):
        docs_hooks.render("<!-- generated: nope -->", where="x.md")


def _command_lines() -> list[tuple[str, str]]:
    found = []
    for path, body in docs_hooks.code_blocks("sh"):
        logical = body.replace("\\\n", " ")
        for line in logical.splitlines():
            words = shlex.split(line.split("  #")[0], comments=True)
            if words[:3] == ["python", "-m", "otonav"]:
                words = ["otonav", *words[3:]]
            if words[:1] == ["otonav"]:
                found.append((f"{path.relative_to(ROOT)}: {line.strip()}", shlex.join(words[1:])))
    return found


COMMANDS = _command_lines()


def test_the_docs_show_commands() -> None:
    assert len(COMMANDS) >= 40


@pytest.mark.parametrize(("where", "argv"), COMMANDS, ids=[w for w, _ in COMMANDS])
def test_every_command_line_in_the_docs_parses(where: str, argv: str) -> None:
    args = shlex.split(argv.replace("[--force]", "--force"))
    if not args or args[0].startswith("-"):
        args = ["run", *args]  # what otonav.cli.main does with no command
    if args in (["--version"], ["run", "--version"]):
        return
    try:
        build_parser().parse_args(args)
    except SystemExit as exc:
        pytest.fail(f"{where}: the parser refuses it (exit {exc.code})")


YAML_BLOCKS = docs_hooks.code_blocks("yaml")


@pytest.mark.parametrize(
    ("path", "body"), YAML_BLOCKS, ids=[f"{p.name}:{i}" for i, (p, _) in enumerate(YAML_BLOCKS)]
)
def test_every_yaml_block_validates(path: Path, body: str) -> None:
    included = docs_hooks.included_file(body)
    data = yaml.safe_load(included.read_text() if included else body)
    valid = []
    for model in (StackConfig, ScenarioConfig, SweepSpec):
        try:
            model.model_validate_json(json.dumps(data))  # as the file loaders do
            valid.append(model.__name__)
        except ValueError:
            pass
    assert valid, f"{path.name}: a YAML block that is no stack, scenario or sweep file:\n{body}"


def test_every_included_file_is_exercised_by_a_test() -> None:
    tests = "\n".join(p.read_text() for p in (ROOT / "tests").rglob("*.py"))
    for lang in ("python", "yaml"):
        for path, body in docs_hooks.code_blocks(lang):
            included = docs_hooks.included_file(body)
            if included is None:
                continue
            assert included.is_file(), f"{path.name} includes a missing file {included}"
            assert included.name in tests, f"no test names {included}"


def test_the_docs_remap_examples_remap_and_say_what_is_live() -> None:
    """Issue 39 item 8: concepts/launch.md's only remap example was a no-op
    (``{/cmd_vel_nav: /cmd_vel_nav}``), and the tutorial mapped ``ros2 param set`` (live)
    to ``--set`` (launch time)."""
    remaps = []
    for path, body in docs_hooks.code_blocks("yaml"):
        included = docs_hooks.included_file(body)
        data = yaml.safe_load(included.read_text() if included else body)
        for entry in data.get("actors", []) if isinstance(data, dict) else []:
            remaps += [(path.name, a, b) for a, b in entry.get("remap", {}).items()]
    assert {name for name, _a, _b in remaps} >= {"launch.md", "own-node.md"}
    assert [r for r in remaps if r[1] == r[2]] == []
    tutorial = (ROOT / "docs" / "getting-started" / "tutorial.md").read_text()
    (row,) = [ln for ln in tutorial.splitlines() if ln.startswith("|") and "ros2 param set" in ln]
    assert "--set" not in row
    assert "launch-time" in tutorial


def test_the_api_reference_turns_sphinx_roles_into_links() -> None:
    """Issue 39 item 7: 112 raw roles showed as text. The griffe extension the docs build
    loads makes each an autorefs link, resolved in the docstring's scope, and a ``::``
    marker a colon (``make test-docs`` then searches the built site for any left)."""
    import griffe
    import griffe_sphinx_roles

    runtime = griffe.load("otonav.runtime", search_paths=[str(ROOT)])
    clock = runtime["_clock"]
    text = (
        "The :class:`~otonav.runtime._system.System` and :class:`Clock`; see :func:`now()`."
        "\n\nLike this::\n\n    code\n"
    )
    converted = griffe_sphinx_roles.convert(text, clock)
    assert ":class:" not in converted
    assert ":func:" not in converted
    link = '<autoref identifier="otonav.runtime.{}" optional><code>{}</code></autoref>'
    assert link.format("_system.System", "System") in converted
    assert link.format("_clock.Clock", "Clock") in converted
    assert "Like this:\n" in converted
    assert "::" not in converted
