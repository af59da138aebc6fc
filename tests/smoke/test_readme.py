"""The README's Python examples run, as a user would run them, so they cannot drift: each
fenced ``python`` block is matched to how it is meant to be used (a test file for pytest,
an ``async def`` to await, a notebook cell with a top-level ``async for``). A block no
runner claims fails the suite. The README's claims about what the ``test`` extra
installs and what a failing example test reports are checked here too."""

from __future__ import annotations

import ast
import asyncio
import contextlib
import io
import re
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from otonav.scenario import ScenarioConfig, run_scenario

pytestmark = pytest.mark.smoke

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text()
BLOCKS = re.findall(r"^```python\n(.*?)^```$", README, flags=re.DOTALL | re.MULTILINE)
INI = """[pytest]
asyncio_default_fixture_loop_scope = function
"""


def _block(marker: str) -> str:
    (block,) = [str(b) for b in BLOCKS if marker in b]
    return block


RUNNERS: dict[str, str] = {
    "def test_reaches_the_goal": "the pytest example (test_my_robot.py)",
    "def test_the_navigator_still_decides_the_same": "the replay regression suite",
    "async for record in sweep_results": "the sweep from Python",
    "async def watch": "the live embedding",
    "async def simulate": "the fast simulations",
    "generate_world(7, DENSE)": "the world generator",
}


def test_every_python_block_has_a_runner() -> None:
    assert len(BLOCKS) >= len(RUNNERS)
    for block in BLOCKS:
        claimed = [marker for marker in RUNNERS if marker in block]
        assert len(claimed) == 1, f"no runner (or several) for this README block:\n{block}"


def test_the_test_extra_is_what_the_readme_says() -> None:
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    names = {re.split(r"[<>=\[]", dep)[0] for dep in extras["optional-dependencies"]["test"]}
    said = re.search(r"`test` extra, which adds ([^:]*?):", README.replace("\n", " "))
    assert said is not None
    listed = set(re.findall(r"[a-z][a-z0-9-]+", said.group(1).replace(" and ", ", ")))
    assert listed == names


def test_the_pytest_example_passes_and_its_failure_reads_as_the_readme_says(
    pytester: pytest.Pytester,
) -> None:
    pytester.makeini(INI)
    block = _block("def test_reaches_the_goal")
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
    # What the README says about the error's type is true:
    says_group = "ExceptionGroup" in README.split("## Scenario files")[0].split("def test_")[-1]
    assert says_group == ("ExceptionGroup" in text)


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
    namespace: dict[str, Any] = {"__name__": "readme"}
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        if call is None:
            flags = ast.PyCF_ALLOW_TOP_LEVEL_AWAIT
            code = compile(source, "README.md", "exec", flags=flags)
            result = eval(code, namespace)  # a coroutine: the cell's top-level awaits
            if result is not None:
                asyncio.run(result)
        else:
            exec(compile(source, "README.md", "exec"), namespace)
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
    exec(compile(_block("generate_world(7, DENSE)"), "README.md", "exec"), namespace)
    assert namespace["world"].reachable
    assert [w.scenario.expect for w in namespace["family"]] == ["unreachable"] * 3
