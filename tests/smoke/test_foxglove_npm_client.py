"""Foxglove that drives, tried with a third-party client: ``@foxglove/ws-protocol`` from
the npm registry, run by node (``tests/npm/drive.mjs``), sets a parameter (the robot's
top speed) and publishes a goal from a client channel; the goal is reached, as slowly as
the parameter says, and the change is in the recording (issue 25)."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path
from typing import Any

import anyio
import pytest

from otonav.actors import topics
from otonav.embed import open_live_stack
from otonav.foxglove import FoxgloveServer, LiveView
from otonav.record._reader import read_messages
from otonav.runtime import RealTime, until
from otonav.stack import StackConfig
from otonav.stack._config import FoxgloveConfig

pytestmark = pytest.mark.smoke

NPM_DIR = Path(__file__).resolve().parents[1] / "npm"
CEILING = 90.0
"""Wall seconds: a hang, never a timing assertion."""
GOAL = (1.0, 0.3)
SLOW = 0.15


@pytest.fixture(scope="module")
def node_client() -> list[str]:
    """The command that runs the npm client, its packages installed from the lock file."""
    node, npm = shutil.which("node"), shutil.which("npm")
    assert node, "node is needed (Node.js 20, as on every machine here)"
    assert npm, "npm is needed (it comes with Node.js)"
    if not (NPM_DIR / "node_modules" / "@foxglove" / "ws-protocol").is_dir():
        subprocess.run(
            [npm, "ci", "--no-audit", "--no-fund", "--loglevel=error"],
            cwd=NPM_DIR,
            check=True,
            timeout=300,
        )
    return [node, str(NPM_DIR / "drive.mjs")]


@pytest.mark.asyncio
async def test_the_npm_client_sets_a_parameter_and_sends_a_goal_that_is_reached(
    node_client: list[str], tmp_path: Path
) -> None:
    server = FoxgloveServer(FoxgloveConfig(port=0))
    view = LiveView(server)
    record = tmp_path / "live.mcap"
    stack = StackConfig.model_validate({"nav": {"planner": "stop"}})
    events: list[dict[str, Any]] = []
    with anyio.fail_after(CEILING):
        async with open_live_stack(
            stack, time=RealTime(4.0), record_to=record, extra_actors=(view,)
        ) as live:
            view.serve_parameters(live.system.actor(a.name) for a in live.graph().actors)
            args = [*node_client, server.url, str(GOAL[0]), str(GOAL[1]), str(SLOW)]
            async with await anyio.open_process(args) as client:
                assert client.stdout is not None
                assert client.stdin is not None
                lines = client.stdout
                buffer = b""
                while not any(e["event"] == "goalSent" for e in events):
                    buffer += await lines.receive()
                    *complete, buffer = buffer.split(b"\n")
                    events.extend(json.loads(line) for line in complete if line)
                trip = [live.now()]

                def near() -> float:
                    truth = live.hal.ground_truth()
                    return float(((truth.x - GOAL[0]) ** 2 + (truth.y - GOAL[1]) ** 2) ** 0.5)

                await until(
                    lambda: near() < 0.15,
                    within=30.0,
                    clock=live.clock,
                    what="the robot reached the npm client's goal",
                )
                trip.append(live.now())
                await client.stdin.aclose()
                await client.wait()
    info = next(e for e in events if e["event"] == "serverInfo")
    assert {"clientPublish", "parameters"} <= set(info["capabilities"])
    (changed,) = [e for e in events if e["event"] == "parameterValues" and e["id"] == "set"]
    assert changed["parameters"] == [{"name": "nav.params.max_v", "value": SLOW}]
    assert not [e for e in events if e["event"] in ("status", "error")], events
    assert view.client_messages == 1
    distance = (GOAL[0] ** 2 + GOAL[1] ** 2) ** 0.5
    assert trip[1] - trip[0] > distance / (SLOW * 1.2)  # as slow as the parameter says
    lines_out = [m.msg for _t, _s, m in read_messages(record, [topics.ROSOUT])]
    assert any("parameter nav.params.max_v: 0.4 -> 0.15" in line for line in lines_out)
