"""The Python examples of the docs site and the README run, as a user would run them, so
they cannot drift: each fenced ``python`` block is matched to how it is meant to be used (a
test file for pytest, an ``async def`` to await, a notebook cell with a top-level ``async
for``, a script). A block no runner claims fails the suite. A block that includes a file
whole (``--8<--``) is that file, which its own tests run. The install page's claims about
what each extra installs and the first-test page's about what a failing example reports
are checked here too."""

from __future__ import annotations

import ast
import asyncio
import contextlib
import io
import re
import shutil
import sys
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from otonav.scenario import ScenarioConfig, run_scenario

pytestmark = pytest.mark.smoke

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

import docs_hooks  # noqa: E402

BLOCKS = [
    body for _path, body in docs_hooks.code_blocks("python") if not docs_hooks.included_file(body)
]
FIRST_TEST = (ROOT / "docs" / "getting-started" / "first-test.md").read_text()
INSTALL = (ROOT / "docs" / "getting-started" / "install.md").read_text()
INI = """[pytest]
asyncio_default_fixture_loop_scope = function
"""


def _block(marker: str) -> str:
    (block,) = [str(b) for b in BLOCKS if marker in b]
    return block


RUNNERS: dict[str, str] = {
    "def test_reaches_the_goal(": "the first scenario test (test_my_robot.py)",
    "def test_reaches_the_goal_in_20_s": "the README's example",
    "def test_my_planner_arrives": "the tutorial's test of the user's node",
    "virtual_loop_factory()": "the sim-time concept's loop",
    "FakeHardware()": "the HAL concept's fake",
    "def test_the_navigator_still_decides_the_same": "the replay regression suite",
    "async for record in sweep_results": "the sweep from Python",
    "async def watch": "the live embedding",
    "async def simulate": "the fast simulations",
    "generate_world(7, DENSE)": "the world generator",
    "time=RealTime(20.0)": "the time mode as a value",
}


def test_every_python_block_has_a_runner() -> None:
    assert len(BLOCKS) >= len(RUNNERS)
    for block in BLOCKS:
        claimed = [marker for marker in RUNNERS if marker in block]
        assert len(claimed) == 1, f"no runner (or several) for this docs block:\n{block}"


@pytest.mark.parametrize("extra", ["test", "can", "foxglove", "ray", "service", "docs"])
def test_each_extra_adds_what_the_install_page_says(extra: str) -> None:
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    names = {re.split(r"[<>=\[]", dep)[0] for dep in extras["optional-dependencies"][extra]}
    row = re.search(rf"^\| `{extra}` \| ([^|]*) \|", INSTALL, flags=re.MULTILINE)
    assert row is not None, f"install.md has no row for the {extra} extra"
    assert set(re.findall(r"[a-z][a-z0-9-]+", row.group(1))) == names


def test_the_first_test_passes_and_its_failure_reads_as_the_page_says(
    pytester: pytest.Pytester,
) -> None:
    pytester.makeini(INI)
    block = _block("def test_reaches_the_goal(")
    pytester.makepyfile(test_my_robot=block)
    passed = pytester.runpytest_subprocess("-q", "-p", "no:cacheprovider")
    passed.assert_outcomes(passed=2)

    pytester.makepyfile(test_my_robot=block.replace("[0.8, 0.4]", "[0.0]"))
    failed = pytester.runpytest_subprocess(
        "-q", "-p", "no:cacheprovider", "--otonav-artifacts=kept"
    )
    failed.assert_outcomes(failed=1)
    text = failed.stdout.str()
    assert "reaching the goal not met within 20 s of sim time (gave up at sim time 20.0" in text
    assert "SimTimeoutError" in text
    assert "otonav artifacts" in text
    assert list((pytester.path / "kept").rglob("trajectory.png"))
    # What the page says about the error's type is true:
    assert ("ExceptionGroup" in FIRST_TEST) == ("ExceptionGroup" in text)
    assert "The error is the plain `SimTimeoutError`" in FIRST_TEST


def test_the_readme_example_passes(pytester: pytest.Pytester) -> None:
    pytester.makeini(INI)
    pytester.makepyfile(test_readme=_block("def test_reaches_the_goal_in_20_s"))
    pytester.runpytest_subprocess("-q", "-p", "no:cacheprovider").assert_outcomes(passed=1)


def test_the_tutorials_node_test_passes(pytester: pytest.Pytester) -> None:
    pytester.makeini(INI)
    shutil.copytree(ROOT / "examples" / "my_nodes", pytester.path / "examples" / "my_nodes")
    pytester.makepyfile(test_my_node=_block("def test_my_planner_arrives"))
    pytester.runpytest_subprocess("-q", "-p", "no:cacheprovider").assert_outcomes(passed=1)


@pytest.mark.parametrize(
    ("marker", "printed"),
    [("virtual_loop_factory()", "3600.0\n"), ("FakeHardware()", "left_velocity=1.0")],
    ids=["sim-time", "hal"],
)
def test_a_script_example_prints_what_its_comment_says(marker: str, printed: str) -> None:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(_block(marker), "docs", "exec"), {"__name__": "docs"})
    assert printed in out.getvalue()


def test_the_replay_regression_suite_runs(pytester: pytest.Pytester) -> None:
    pytester.makeini(INI)
    run_scenario(
        ScenarioConfig(name="short", scene="empty", sim_budget=2.0),
        out_dir=pytester.path / "regressions" / "short",
        plot=False,
    )
    (pytester.path / "regressions" / "short" / "recording.mcap").rename(
        pytester.path / "regressions" / "short.mcap"
    )
    pytester.makepyfile(test_regressions=_block("def test_the_navigator_still_decides_the_same"))
    pytester.runpytest_subprocess("-q", "-p", "no:cacheprovider").assert_outcomes(passed=1)


def _run_async(source: str, call: str | None) -> str:
    """Run a block: its ``call`` coroutine function, or the block itself as a notebook
    cell (top-level await); return what it printed."""
    namespace: dict[str, Any] = {"__name__": "docs"}
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        if call is None:
            flags = ast.PyCF_ALLOW_TOP_LEVEL_AWAIT
            code = compile(source, "docs", "exec", flags=flags)
            result = eval(code, namespace)  # a coroutine: the cell's top-level awaits
            if result is not None:
                asyncio.run(result)
        else:
            exec(compile(source, "docs", "exec"), namespace)
            asyncio.run(namespace[call]())
    return printed.getvalue()


@pytest.mark.parametrize(
    ("marker", "call", "check"),
    [
        (
            "async def watch",
            "watch",
            lambda out, cwd: "actors" in out and (cwd / "live.mcap").exists(),
        ),
        (
            "async def simulate",
            "simulate",
            lambda out, cwd: out.startswith("True ") and (cwd / "out/run1/trajectory.png").exists(),
        ),
        (
            "async for record in sweep_results",
            None,
            lambda out, cwd: out.split() == ["empty", "0", "passed"],
        ),
    ],
    ids=["live", "simulate", "sweep"],
)
def test_an_embedding_example_runs(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    marker: str,
    call: str | None,
    check: Callable[[str, Path], bool],
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sweep.yaml").write_text("name: readme\nscenarios: [empty]\nseeds: [0]\n")
    out = _run_async(_block(marker), call)
    assert check(out, tmp_path), out


def test_the_world_generator_example_runs() -> None:
    namespace: dict[str, Any] = {}
    exec(compile(_block("generate_world(7, DENSE)"), "docs", "exec"), namespace)
    assert namespace["world"].reachable
    assert [w.scenario.expect for w in namespace["family"]] == ["unreachable"] * 3


def test_the_time_mode_example_runs_in_real_time() -> None:
    """start-a-stack.md: the same scenario in real time, scaled, by passing one value."""
    namespace: dict[str, Any] = {"__name__": "docs"}
    exec(compile(_block("time=RealTime(20.0)"), "docs", "exec"), namespace)
    verdict = namespace["verdict"]
    # Paced: the wall time follows the sim time at about the scale (the loop is not
    # virtual); a virtual run of this scenario takes a small fraction of it.
    assert verdict.sim_time_s / verdict.wall_time_s < 40
