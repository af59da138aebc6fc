"""The otonav pytest plugin (entry point ``otonav``).

- ``@pytest.mark.sim`` runs an async test (and its async fixtures of the same loop
  scope) on a fresh :class:`~otonav.runtime.VirtualTimeLoop`: ``anyio.sleep``,
  ``asyncio.timeout`` and ``until(...)`` are sim time. Marker options: ``wall_ceiling``
  (s, default 60) and ``deadlock_grace`` (s, default 0.5). Unmarked tests keep
  pytest-asyncio's ordinary loop.
- ``otonav_artifacts``: a directory for this test's artifacts (recordings, plots). When
  the test fails they are kept under ``--otonav-artifacts`` (default
  ``out/test-artifacts``), a trajectory plot is drawn for each recording, and the
  failure report names the paths. When it passes they are deleted.
"""

from __future__ import annotations

import asyncio
import inspect
import re
import shutil
from collections.abc import Callable, Generator, Mapping
from pathlib import Path

import pytest

from otonav.errors import UsageError
from otonav.runtime._errors import SimTimeoutError
from otonav.runtime._loop import DEADLOCK_GRACE, virtual_loop_factory

DEFAULT_WALL_CEILING = 60.0
DEFAULT_ARTIFACTS = "out/test-artifacts"
_DIR_KEY = pytest.StashKey[Path]()


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("otonav")
    group.addoption(
        "--otonav-artifacts",
        default=None,
        metavar="DIR",
        help=f"where failing scenario tests keep their recordings (default {DEFAULT_ARTIFACTS})",
    )
    parser.addini("otonav_artifacts", "default for --otonav-artifacts", default=DEFAULT_ARTIFACTS)


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers",
        "sim(wall_ceiling=60.0, deadlock_grace=0.5): run this async test on otonav's "
        "virtual-time loop (sim time is loop time)",
    )


@pytest.hookimpl(tryfirst=True)
def pytest_pycollect_makeitem(collector: pytest.Collector, name: str, obj: object) -> None:
    """``@pytest.mark.sim`` implies ``@pytest.mark.asyncio`` (also in strict mode)."""
    if not inspect.iscoroutinefunction(obj):
        return
    marks = [m.name for m in getattr(obj, "pytestmark", [])]
    if "sim" in marks and "asyncio" not in marks:
        pytest.mark.asyncio(obj)


def pytest_asyncio_loop_factories(
    config: pytest.Config, item: pytest.Item
) -> Mapping[str, Callable[[], asyncio.AbstractEventLoop]]:
    marker = item.get_closest_marker("sim")
    if marker is None:
        return {"asyncio": asyncio.new_event_loop}
    return {
        "virtual": virtual_loop_factory(
            wall_ceiling=marker.kwargs.get("wall_ceiling", DEFAULT_WALL_CEILING),
            deadlock_grace=marker.kwargs.get("deadlock_grace", DEADLOCK_GRACE),
        )
    }


def _artifacts_root(config: pytest.Config) -> Path:
    option = config.getoption("--otonav-artifacts")
    root = Path(option if option else str(config.getini("otonav_artifacts")))
    return root if root.is_absolute() else Path(config.rootpath) / root


@pytest.fixture
def otonav_artifacts(request: pytest.FixtureRequest) -> Path:
    """This test's artifact directory (kept only if the test fails)."""
    name = re.sub(r"[^A-Za-z0-9_.-]+", "_", request.node.nodeid).strip("_")
    path = _artifacts_root(request.config) / name
    if path.exists():
        shutil.rmtree(path)
    path.mkdir(parents=True)
    request.node.stash[_DIR_KEY] = path
    return path


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(
    item: pytest.Item, call: pytest.CallInfo[None]
) -> Generator[None, pytest.TestReport, None]:
    outcome = yield
    report: pytest.TestReport = outcome.get_result()
    if report.failed and call.excinfo is not None:
        short = _short_failure(item, call.excinfo)
        if short is not None:
            report.longrepr = short
    path = item.stash.get(_DIR_KEY, None)
    if path is None or report.when != "call":
        return
    if report.failed:
        lines = []
        for recording in sorted(path.rglob("*.mcap")):
            lines.append(f"recording: {recording}")
            png = recording.parent / "trajectory.png"
            if not png.exists():
                try:
                    from otonav.scenario._replay import plot_recording

                    png = plot_recording(recording, png)
                except Exception as exc:  # the report must still name the recording
                    lines.append(f"(no trajectory plot: {exc})")
                    continue
            lines.append(f"trajectory: {png}")
        report.sections.append(("otonav artifacts", "\n".join(lines) or f"(none in {path})"))
    else:
        shutil.rmtree(path, ignore_errors=True)


def _short_failure(item: pytest.Item, excinfo: pytest.ExceptionInfo[BaseException]) -> str | None:
    """A user's wiring or config mistake, or a sim-time wait that ran out, as the line
    that says it and where in the test it came from, not the library's source (issue
    39); None for any other failure (pytest's own report)."""
    if not excinfo.errisinstance((UsageError, SimTimeoutError)):
        return None
    where = ""
    for entry in reversed(excinfo.traceback):
        if Path(str(entry.path)) == Path(str(item.path)):
            where = f"{entry.path}:{entry.lineno + 1}: "
            break
    return f"{where}{excinfo.typename}: {excinfo.value}"
