"""The example service (examples/service/app.py), started for real on 127.0.0.1 with an
ephemeral port and driven over HTTP: a responsive host loop while simulations run, a
live pose stream, cancellation leaving an indexed recording, bad input as 4xx with the
CLI's message, and the same verdict and recording bytes from every way of running."""

from __future__ import annotations

import asyncio
import itertools
import json
import math
import selectors
import signal
import statistics
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import httpx
import pytest

from otonav.embed import run_scenario_async
from otonav.record._reader import summarize
from otonav.scenario import run_scenario
from otonav.scenario._builtin import BUILTIN

pytestmark = pytest.mark.smoke

REPO = Path(__file__).resolve().parents[2]
APP = REPO / "examples" / "service" / "app.py"
START_CEILING_S = 30.0
# The probes' latency is a figure, printed here and measured by benchmarks/embed_bench.py;
# a timed assertion (p90 < 50 ms, then < 0.5 s) failed on a loaded machine (load average
# 11 on 2 cores: p90 56-58 ms) with nothing wrong. What is asserted is in sim time.
PROBES = 25
# Reaches no goal (the navigator stops 8 cm short of a 1 mm tolerance): it runs until
# cancelled or its sim budget (minutes of sim time) is spent.
ENDLESS: dict[str, Any] = {
    "name": "endless",
    "scene": "empty",
    "goal": {"x": 3.0, "y": -1.0},
    "goal_tolerance": 0.001,
    "sim_budget": 600.0,
}
VOLATILE = {"wall_time_s", "rtf", "recording", "plot"}


@dataclass(frozen=True, slots=True)
class Server:
    url: str
    out: Path
    process: subprocess.Popen[str]


def _first_line(process: subprocess.Popen[str], within: float) -> str:
    assert process.stdout is not None
    with selectors.DefaultSelector() as selector:
        selector.register(process.stdout, selectors.EVENT_READ)
        if not selector.select(within):
            raise AssertionError(f"the service printed no address within {within} s")
    return process.stdout.readline()


@pytest.fixture(scope="module")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    out = tmp_path_factory.mktemp("service")
    stderr = (out / "stderr.log").open("w")
    process = subprocess.Popen(
        [sys.executable, str(APP), "--port", "0", "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=stderr,
        text=True,
        cwd=out,
    )
    try:
        line = _first_line(process, START_CEILING_S)
        assert "listening on http://127.0.0.1:" in line, line
        url = line.split()[-1]
        # The socket listens before uvicorn starts: this waits for startup, no polling.
        health = httpx.get(f"{url}/health", timeout=START_CEILING_S)
        assert health.json()["live"] == "running"
        yield Server(url, out, process)
    finally:
        process.terminate()  # SIGTERM: uvicorn shuts down, the lifespan closes the stack
        try:
            code = process.wait(timeout=20)
        finally:
            if process.poll() is None:
                process.kill()
            stderr.close()
            if process.stdout is not None:
                process.stdout.close()
    log = (out / "stderr.log").read_text()
    # After its graceful shutdown the service exits 128 + the signal it caught.
    assert code == 128 + signal.SIGTERM, log
    assert "Traceback" not in log, log
    live = summarize(out / "live.mcap")
    assert live.truncated is False
    assert live.message_count > 0


@pytest.fixture
def client(server: Server) -> Iterator[httpx.Client]:
    with httpx.Client(base_url=server.url, timeout=10.0) as http:
        yield http


def _start(client: httpx.Client, body: dict[str, Any]) -> str:
    response = client.post("/runs", json=body)
    assert response.status_code == 202, response.text
    run_id: str = response.json()["id"]
    return run_id


def _wait_status(client: httpx.Client, run_id: str, until: Any, within: float) -> dict[str, Any]:
    """Ask until ``until(run)``; each ask waits up to 50 ms server-side for the run's end."""
    deadline = time.monotonic() + within
    while True:
        run: dict[str, Any] = client.get(f"/runs/{run_id}", params={"wait": 0.05}).json()
        if until(run):
            return run
        assert time.monotonic() < deadline, f"run never satisfied the condition: {run}"


def test_health_answers_while_simulations_run(client: httpx.Client) -> None:
    """Every probe is answered while both simulations run, and the answers come at many
    instants of the simulations' sim time: the service serves between their steps (a
    simulation on its loop would hold every request until it ended or the client's
    timeout, a hang ceiling, gave up)."""
    runs = [_start(client, {"scenario": ENDLESS}) for _ in range(2)]
    for run_id in runs:
        _wait_status(client, run_id, lambda r: r["status"] == "running", within=10)
    first = [client.get(f"/runs/{r}").json()["sim_time_s"] for r in runs]
    latencies = []
    sim_at_answer: list[float] = []
    with httpx.Client(base_url=client.base_url, timeout=5.0) as probe:
        for _ in range(PROBES):
            start = time.perf_counter()
            response = probe.get("/health")
            latencies.append(time.perf_counter() - start)
            assert response.status_code == 200
            assert response.json()["runs_active"] == 2
            sim_at_answer.append(probe.get(f"/runs/{runs[0]}").json()["sim_time_s"])
    # Both simulations were running through every probe (and made progress).
    after = [client.get(f"/runs/{r}").json() for r in runs]
    assert all(r["status"] == "running" for r in after)
    assert all(a["sim_time_s"] > f for a, f in zip(after, first, strict=True))
    for run_id in runs:
        assert client.delete(f"/runs/{run_id}").json()["status"] == "cancelled"
    assert sim_at_answer == sorted(sim_at_answer)
    assert len(set(sim_at_answer)) >= 5, f"answered at sim instants {sim_at_answer} only"
    latencies.sort()
    print(
        f"\n/health during 2 simulations + the live robot: median "
        f"{statistics.median(latencies) * 1e3:.1f} ms, "
        f"p90 {latencies[int(0.9 * (len(latencies) - 1))] * 1e3:.1f} ms, "
        f"max {latencies[-1] * 1e3:.1f} ms over {len(latencies)} probes (a figure, not a test)"
    )


def test_cancelled_run_leaves_an_indexed_recording(client: httpx.Client) -> None:
    run_id = _start(client, {"scenario": ENDLESS})
    _wait_status(client, run_id, lambda r: (r["sim_time_s"] or 0) >= 2.0, within=20)
    response = client.delete(f"/runs/{run_id}")
    assert response.status_code == 200
    run = response.json()
    assert run["status"] == "cancelled"
    assert run["recording"] is not None
    summary = summarize(run["recording"])
    assert summary.truncated is False
    assert summary.end_ns / 1e9 >= 2.0
    verdict = json.loads(summary.metadata["otonav"]["verdict"])
    assert verdict["passed"] is False
    assert "run ended early (CancelledError" in verdict["reason"]
    # Cancelling again, or asking, says the same.
    assert client.delete(f"/runs/{run_id}").json()["status"] == "cancelled"


def _events(response: httpx.Response) -> Iterator[dict[str, float]]:
    for line in response.iter_lines():
        if line.startswith("data: "):
            yield json.loads(line.removeprefix("data: "))


def _host_subscribers(client: httpx.Client, topic: str) -> int:
    graph = client.get("/live/graph").json()
    (entry,) = [t for t in graph["topics"] if t["name"] == topic]
    return sum(1 for s in entry["subscriptions"] if s["actor"] == "host")


def test_live_pose_stream_moves_after_a_goal(client: httpx.Client) -> None:
    with client.stream("GET", "/live/pose", params={"hz": 20}, timeout=5.0) as response:
        assert response.status_code == 200
        assert response.headers["content-type"].startswith("text/event-stream")
        events = _events(response)
        before = [next(events) for _ in range(5)]
        times = [e["t"] for e in before]
        assert all(b - a >= 0.05 - 1e-6 for a, b in itertools.pairwise(times))
        assert _host_subscribers(client, "/odom") == 1
        start = before[-1]
        posted = client.post("/live/goal", json={"x": 1.0, "y": 0.2})
        assert posted.status_code == 202, posted.text
        deadline = time.monotonic() + 15.0
        for event in events:
            if math.hypot(event["x"] - start["x"], event["y"] - start["y"]) > 0.2:
                break
            assert time.monotonic() < deadline, f"the robot did not move: {event}"
    # The stream's mailbox left the topic with the client (no leak per connection).
    deadline = time.monotonic() + 5.0
    while _host_subscribers(client, "/odom"):
        assert time.monotonic() < deadline, "the closed stream still subscribes to /odom"


def test_bad_input_gets_4xx_in_the_words_of_the_request(client: httpx.Client) -> None:
    """Each error names the request's field (``scenario``, ``set``, ``seed``), never a
    CLI flag, and says each thing once."""
    cases: list[tuple[str, str, dict[str, Any], int, str]] = [
        ("POST", "/runs", {"content": b"{nope"}, 400, "request body: invalid JSON"),
        ("POST", "/runs", {"json": {"bogus": 1}}, 400, "request: bogus: unknown key"),
        (
            "POST",
            "/runs",
            {"json": {"scenario": "nope"}},
            400,
            "scenario: 'nope' is not a built-in scenario (acceptance, empty, ",
        ),
        (
            "POST",
            "/runs",
            {"json": {"set": ["nav.kp_lin=-1"]}},
            400,
            "set: nav.kp_lin: Input should be",
        ),
        ("POST", "/runs", {"json": {"set": ["nav.bogus=1"]}}, 400, "set nav.bogus: unknown key"),
        ("POST", "/runs", {"json": {"set": ["nav"]}}, 400, "set 'nav': expected key.path=value"),
        ("POST", "/runs", {"json": {"scenario": {"goal_tolerance": -1}}}, 400, "scenario: "),
        (
            "POST",
            "/runs",
            {"json": {"scenario": {"scene": "mars"}}},
            400,
            "scenario: scene 'mars' is ",
        ),
        (
            "POST",
            "/runs",
            {"json": {"scenario": {"goal": {"x": 40, "y": 0}}}},
            400,
            "scenario: goal: (40, 0) is outside the arena",
        ),
        ("POST", "/runs", {"json": {"scenario": "../etc/passwd"}}, 400, "reads no files"),
        ("POST", "/runs", {"json": {"scenario": {"scene": "/etc/passwd"}}}, 400, "no files"),
        ("POST", "/runs", {"json": {"seed": -3}}, 400, "seed: Input should be greater than"),
        ("GET", "/runs/nope", {}, 404, "no run 'nope'"),
        ("DELETE", "/runs/nope", {}, 404, "no run 'nope'"),
        ("GET", "/runs/nope/recording", {}, 404, "no run 'nope'"),
        ("GET", "/live/pose", {"params": {"hz": "0"}}, 400, "hz='0'"),
        ("POST", "/live/goal", {"json": {"x": "far", "y": 0}}, 400, "goal: x: "),
        ("POST", "/live/goal", {"json": {"x": 40, "y": 0}}, 400, "goal (40, 0) is outside"),
    ]
    for method, path, kwargs, status, text in cases:
        response = client.request(method, path, **kwargs)
        assert response.status_code == status, (path, kwargs, response.text)
        error = response.json()["error"]
        assert text in error, (path, kwargs, error)
        assert "\n" not in error
        assert "--" not in error, f"a CLI flag in an HTTP error: {error}"
        first = error.split(":")[0].split()[0]
        assert error.count(f"{first}: {first}") == 0, f"says {first!r} twice: {error}"
    health = client.get("/health").json()
    assert health == {"status": "ok", "live": "running", "runs_active": 0}


def test_a_finished_runs_recording_and_plot_are_served(client: httpx.Client) -> None:
    run_id = _start(client, {"scenario": "empty"})
    running = client.get(f"/runs/{run_id}/recording")
    run = client.get(f"/runs/{run_id}", params={"wait": 30}, timeout=40).json()
    assert run["status"] == "passed", run
    if running.status_code != 200:  # asked before the end: refused, not half a file
        assert running.status_code == 409, running.text
        assert "not finished" in running.json()["error"]
    assert run["links"] == {
        "recording": f"/runs/{run_id}/recording",
        "plot": f"/runs/{run_id}/plot",
    }
    recording = client.get(run["links"]["recording"])
    assert recording.status_code == 200
    assert recording.content.startswith(b"\x89MCAP0\r\n")
    assert recording.content == Path(run["recording"]).read_bytes()
    plot = client.get(run["links"]["plot"])
    assert plot.status_code == 200
    assert plot.headers["content-type"] == "image/png"
    assert plot.content.startswith(b"\x89PNG")


def test_a_running_runs_recording_is_refused(client: httpx.Client) -> None:
    run_id = _start(client, {"scenario": ENDLESS})
    _wait_status(client, run_id, lambda r: r["status"] == "running", within=10)
    response = client.get(f"/runs/{run_id}/recording")
    assert response.status_code == 409, response.text
    assert response.json()["error"] == (
        f"run {run_id} is running: its recording is not finished yet (ask again when it ends)"
    )
    assert client.delete(f"/runs/{run_id}").json()["status"] == "cancelled"


def test_the_live_recording_is_capped_and_rotates(tmp_path: Path) -> None:
    """A small cap (one MB) on a fast live robot: the file rotates, old ones go."""
    cap = ["--live-scale", "20", "--live-record-mb", "1", "--live-record-keep", "1"]
    process = subprocess.Popen(
        [sys.executable, str(APP), "--port", "0", "--out", str(tmp_path), *cap],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        url = _first_line(process, START_CEILING_S).split()[-1]
        with httpx.Client(base_url=url, timeout=10.0) as http:
            assert http.post("/live/goal", json={"x": 4.0, "y": 1.5}).status_code == 202
            deadline = time.monotonic() + 60.0
            while not (tmp_path / "live.1.mcap").exists():  # ~40 s of sim: > 1 MB
                assert time.monotonic() < deadline, "the live recording never rotated"
                assert http.get("/health").json()["live"] == "running"
    finally:
        process.terminate()
        process.communicate(timeout=20)
    names = sorted(p.name for p in tmp_path.glob("live*.mcap"))
    assert names == ["live.1.mcap", "live.mcap"]
    for name in names:
        summary = summarize(tmp_path / name)
        assert not summary.truncated
        assert "otonav.world" in summary.metadata
    assert (tmp_path / "live.1.mcap").stat().st_size < 1.2 * 2**20


def _figures(verdict: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in verdict.items() if k not in VOLATILE}


def test_same_verdict_and_recording_from_cli_pytest_embedding_and_service(
    client: httpx.Client, tmp_path: Path
) -> None:
    scenario = BUILTIN["empty"]
    cli = subprocess.Popen(
        [sys.executable, "-m", "otonav", "run", "--scenario", "empty", "--out", "cli"],
        cwd=tmp_path,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        service_id = _start(client, {"scenario": "empty"})
        direct = run_scenario(scenario, out_dir=tmp_path / "direct")
        embedded = asyncio.run(run_scenario_async(scenario, out_dir=tmp_path / "embedded"))
        served = client.get(f"/runs/{service_id}", params={"wait": 30}, timeout=40).json()
        _, err = cli.communicate(timeout=60)
    finally:
        if cli.poll() is None:
            cli.kill()
    assert cli.returncode == 0, err
    assert served["status"] == "passed", served

    verdicts = {
        "cli": json.loads((tmp_path / "cli" / "summary.json").read_text()),
        "direct": direct.as_dict(),
        "embedded": embedded.as_dict(),
        "service": served["verdict"],
    }
    recordings = {
        "cli": tmp_path / "cli" / "recording.mcap",
        "direct": Path(str(direct.recording)),
        "embedded": Path(str(embedded.recording)),
        "service": Path(served["recording"]),
    }
    assert verdicts["direct"]["passed"] is True
    reference = _figures(verdicts["direct"])
    for name, verdict in verdicts.items():
        assert _figures(verdict) == reference, name
    data = recordings["direct"].read_bytes()
    for name, path in recordings.items():
        assert path.read_bytes() == data, f"{name}: {path} differs from {recordings['direct']}"


def test_adversarial_requests_get_4xx_and_reveal_no_files(
    client: httpx.Client, tmp_path: Path
) -> None:
    # Issue 17, item 4. A scene path in an override made the server read a file the
    # client named, and its errors told whether the path existed; these were 500s.
    real = tmp_path / "real.xml"
    real.write_text("<mujoco/>")
    missing = tmp_path / "missing.xml"

    def error(body: dict[str, Any]) -> str:
        response = client.post("/runs", json=body)
        assert response.status_code == 400, (body, response.text)
        message: str = response.json()["error"]
        assert "\n" not in message
        return message

    said_real = error({"set": [f"world.scene={real}"]})
    said_missing = error({"set": [f"world.scene={missing}"]})
    assert "reads no files" in said_real
    assert said_real.replace(str(real), "P") == said_missing.replace(str(missing), "P")
    for name in (str(real), "real.xml", "etc", "nothing-here"):  # no oracle in the cwd either
        assert "reads no files" in error({"scenario": name}), name
    said = [error({"scenario": {"scene": s}}) for s in (str(real), str(missing))]
    assert said[0].replace(str(real), "P") == said[1].replace(str(missing), "P")
    hardware = error({"set": ["hal.kind=can", "hal.can.interface=socketcan"]})
    assert "'hal.kind' is not a key a client may set" in hardware  # the operator's choice

    cases: list[tuple[str, str, dict[str, Any], int]] = [
        ("POST", "/runs", {"content": b'{"scenario": "\xff\xfe"}'}, 400),  # not UTF-8
        ("POST", "/runs", {"content": b"[" * 100_000 + b"]" * 100_000}, 400),  # deep JSON
        ("POST", "/runs", {"json": {"scenario": "s" * 100_000}}, 400),  # a long name
        ("POST", "/runs", {"json": {"scenario": {"name": "n" * 100_000}}}, 400),
        ("POST", "/runs", {"json": {"set": ["world.scene=" + "x" * 100_000]}}, 400),
        ("POST", "/runs", {"content": b'{"scenario": "' + b"s" * (2 << 20) + b'"}'}, 413),
        ("GET", "/runs/x", {"params": {"wait": "nan"}}, 404),
        ("GET", "/live/pose", {"params": {"hz": "nan"}}, 400),
        ("POST", "/live/goal", {"json": {"x": 1e308, "y": 0}}, 400),
    ]
    for method, path, kwargs, status in cases:
        response = client.request(method, path, **kwargs)
        assert response.status_code == status, (path, response.status_code, response.text[:200])
        message = response.json()["error"]
        assert "\n" not in message
        assert len(message) < 500, message[:600]
    run_id = _start(client, {"scenario": "acceptance"})
    for wait in ("nan", "inf", "-inf", "1e999", "soon", "-5"):  # -5 was "no wait" (issue 27)
        response = client.get(f"/runs/{run_id}", params={"wait": wait})
        assert response.status_code == 400, (wait, response.text)
        assert "wait=" in response.json()["error"]
    client.delete(f"/runs/{run_id}")
    assert client.get("/health").json()["status"] == "ok"
