"""The otonav pytest plugin.

``@pytest.mark.sim`` on an async test (pytest-asyncio) runs it, and its async fixtures of
the same loop scope, on a fresh :class:`~otonav.runtime.VirtualTimeLoop`: ``anyio.sleep``,
``asyncio.timeout`` and ``until(...)`` are sim time. Options of the marker:
``wall_ceiling`` (seconds; default 60) and ``deadlock_grace`` (seconds; default 0.5).
Tests without the marker keep pytest-asyncio's ordinary loop.
"""

from __future__ import annotations

import asyncio
import inspect
from collections.abc import Callable, Mapping

import pytest

from otonav.runtime.loop import virtual_loop_factory

DEFAULT_WALL_CEILING = 60.0


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
            deadlock_grace=marker.kwargs.get("deadlock_grace", 0.5),
        )
    }
