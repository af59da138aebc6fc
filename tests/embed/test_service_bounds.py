"""The example service's bounds (issue 27 item 7): 3,000 POSTs all got 202 and memory
grew from 78 to 336 MB. Now the queue is bounded (503 with Retry-After past it) and
finished runs are forgotten after a time or a count (their files stay). In process,
with the service's clock injected: no wall-clock waits."""

from __future__ import annotations

import asyncio
import importlib.util
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

import httpx
import pytest

pytestmark = pytest.mark.smoke

APP = Path(__file__).resolve().parents[2] / "examples" / "service" / "app.py"
ENDLESS: dict[str, Any] = {  # runs until cancelled (minutes of sim time)
    "name": "endless",
    "scene": "empty",
    "goal": {"x": 3.0, "y": -1.0},
    "goal_tolerance": 0.001,
    "sim_budget": 600.0,
}
KEEP_S = 100.0


def _app_module() -> ModuleType:
    spec = importlib.util.spec_from_file_location("otonav_service_app", APP)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


class FakeClock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


async def _scenario(out: Path) -> None:
    clock = FakeClock()
    service = _app_module().Service(
        out_root=out,
        live=False,
        max_runs=1,
        max_queued=1,
        keep_finished=1,
        keep_finished_s=KEEP_S,
        clock=clock,
    )
    app = service.app()
    transport = httpx.ASGITransport(app=app)
    async with (
        service.lifespan(app),
        httpx.AsyncClient(transport=transport, base_url="http://service") as client,
    ):
        running = await client.post("/runs", json={"scenario": ENDLESS})
        queued = await client.post("/runs", json={"scenario": ENDLESS})
        assert (running.status_code, queued.status_code) == (202, 202)
        refused = await client.post("/runs", json={"scenario": ENDLESS})
        assert refused.status_code == 503, refused.text
        assert int(refused.headers["Retry-After"]) >= 1
        assert "--max-queued" in refused.json()["error"]
        assert (await client.get("/health")).json()["runs_active"] == 2

        first, second = running.json()["id"], queued.json()["id"]
        await client.get(f"/runs/{first}?wait=0")
        assert (await client.delete(f"/runs/{first}")).json()["status"] == "cancelled"
        clock.now = 1.0
        assert (await client.delete(f"/runs/{second}")).json()["status"] == "cancelled"
        # A slot is free again.
        again = await client.post("/runs", json={"scenario": ENDLESS})
        assert again.status_code == 202, again.text
        third = again.json()["id"]
        clock.now = 2.0
        await client.delete(f"/runs/{third}")
        # keep_finished=1: only the newest finished run is remembered; its files stay.
        gone = await client.get(f"/runs/{first}")
        assert gone.status_code == 404
        assert "forgotten" in gone.json()["error"]
        assert (out / first).is_dir()
        assert [r["id"] for r in (await client.get("/runs")).json()] == [third]
        # ... and only for keep_finished_s.
        clock.now = 2.0 + KEEP_S
        assert (await client.get("/runs")).json() == []
        assert (await client.get(f"/runs/{third}")).status_code == 404


@pytest.mark.timeout(120)
def test_the_queue_is_bounded_and_finished_runs_are_forgotten(tmp_path: Path) -> None:
    asyncio.run(_scenario(tmp_path))
