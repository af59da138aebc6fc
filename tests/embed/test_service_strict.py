"""The example service takes JSON's types as they are (issue 27 item 9): an empty body,
``"seed": true`` and ``"x": "1"`` were accepted (lax pydantic made them ``{}``, seed 1
and x 1.0); ``wait=-5`` was answered as if no wait had been asked. Each is now a 400
naming the field and what is valid. In process, live robot included."""

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


def _app_module() -> ModuleType:
    spec = importlib.util.spec_from_file_location("otonav_service_app_strict", APP)
    assert spec is not None
    assert spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module


CASES: list[tuple[str, str, dict[str, Any], str]] = [
    ("POST", "/runs", {"content": b""}, "request body: empty; send a JSON object"),
    ("POST", "/runs", {"content": b"  \n"}, "request body: empty; send a JSON object"),
    ("POST", "/runs", {"json": {"seed": True}}, "request: seed: Input should be a valid integer"),
    ("POST", "/runs", {"json": {"seed": "3"}}, "request: seed: Input should be a valid integer"),
    ("POST", "/runs", {"json": {"set": "nav.kp_lin=1"}}, "request: set: Input should be a valid"),
    ("POST", "/live/goal", {"json": {"x": "1", "y": 0}}, "goal: x: Input should be a valid number"),
    (
        "POST",
        "/live/goal",
        {"json": {"x": 1, "y": True}},
        "goal: y: Input should be a valid number",
    ),
    ("POST", "/live/goal", {"content": b""}, "request body: empty; send a JSON object"),
]


async def _scenario(out: Path) -> None:
    service = _app_module().Service(out_root=out, live=True, live_scale=1.0)
    app = service.app()
    transport = httpx.ASGITransport(app=app)
    async with (
        service.lifespan(app),
        httpx.AsyncClient(transport=transport, base_url="http://service") as client,
    ):
        for method, path, kwargs, text in CASES:
            response = await client.request(method, path, **kwargs)
            assert response.status_code == 400, (path, kwargs, response.text)
            error = response.json()["error"]
            assert error.startswith(text), (path, kwargs, error)
            assert "\n" not in error
        assert (await client.get("/health")).json()["runs_active"] == 0  # none started
        # A valid goal with integer coordinates is still a goal (an int is a number).
        ok = await client.post("/live/goal", json={"x": 1, "y": 0})
        assert ok.status_code == 202, ok.text
        # wait must be a number of seconds >= 0: -5 was answered as if not asked.
        run = await client.post("/runs", json={"scenario": "empty", "seed": 3})
        assert run.status_code == 202, run.text
        run_id = run.json()["id"]
        for wait in ("-5", "nan", "inf", "soon"):
            response = await client.get(f"/runs/{run_id}", params={"wait": wait})
            assert response.status_code == 400, (wait, response.text)
            error = response.json()["error"]
            assert error.startswith(f"wait='{wait}': expected a number of seconds >= 0"), error
            assert "at most" in error  # the upper end of the range
        await client.delete(f"/runs/{run_id}")


@pytest.mark.timeout(120)
def test_requests_are_strict_and_wait_is_bounded(tmp_path: Path) -> None:
    asyncio.run(_scenario(tmp_path))
