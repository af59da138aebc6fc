"""Embedding: how long the host's loop waits while simulations run (wall clock).

The embedding tests assert in sim time that the host's loop serves *between* a
simulation's instants (tests/embed); how long each wait is on the wall clock depends on
the machine and its load, so it is a figure, printed here, never asserted (a p90 < 50 ms
assertion failed at load average 11 on 2 cores with nothing wrong: ADR 0055).

1. A ticker on the host's loop (``anyio.sleep(0.005)``) while ``run_scenario_async``
   runs 10 s of sim time: gaps between its wakes (median, p90, max) against the same
   ticker with no simulation, measured in the same run.
2. With ``--service``: the example service (examples/service/app.py) on 127.0.0.1,
   ``GET /health`` latency while two simulations and the live robot run.

    python benchmarks/embed_bench.py [--reps 5] [--service]
"""

from __future__ import annotations

import argparse
import asyncio
import statistics
import subprocess
import sys
import time
from pathlib import Path

import anyio

from otonav.embed import run_scenario_async
from otonav.scenario import GoalSpec, ScenarioConfig

REPO = Path(__file__).resolve().parents[1]
TICK_S = 0.005
ENDLESS = ScenarioConfig(
    name="endless", scene="empty", goal=GoalSpec(x=3.0, y=-1.0), goal_tolerance=0.001,
    sim_budget=10.0,
)  # fmt: skip


def _p90(samples: list[float]) -> float:
    ordered = sorted(samples)
    return ordered[int(0.9 * (len(ordered) - 1))]


def _figures(samples: list[float]) -> str:
    ordered = sorted(samples)
    p90 = _p90(ordered)
    return (
        f"median {statistics.median(ordered) * 1e3:6.2f} ms  p90 {p90 * 1e3:6.2f} ms  "
        f"max {ordered[-1] * 1e3:6.2f} ms  ({len(ordered)} samples)"
    )


async def _gaps(with_simulation: bool) -> list[float]:
    gaps: list[float] = []

    async def ticker() -> None:
        last = time.perf_counter()
        while True:
            await anyio.sleep(TICK_S)
            now = time.perf_counter()
            gaps.append(now - last)
            last = now

    async with anyio.create_task_group() as tg:
        tg.start_soon(ticker)
        if with_simulation:
            await run_scenario_async(ENDLESS, out_dir=None, plot=False)
        else:
            await anyio.sleep(1.0)
        tg.cancel_scope.cancel()
    return gaps


def host_loop(reps: int) -> None:
    idle: list[float] = []
    busy: list[float] = []
    for _ in range(reps):  # interleaved, so both see the same machine
        idle += asyncio.run(_gaps(False))
        busy += asyncio.run(_gaps(True))
    print(f"host ticker ({TICK_S * 1e3:.0f} ms sleeps), gap between wakes:")
    print(f"  idle host             {_figures(idle)}")
    print(f"  during a simulation   {_figures(busy)}")
    print(f"  ratio of p90s         {_p90(busy) / _p90(idle):.2f}x")


def service(probes: int) -> None:
    import tempfile

    import httpx

    with tempfile.TemporaryDirectory() as out:
        process = subprocess.Popen(
            [sys.executable, str(REPO / "examples/service/app.py"), "--port", "0", "--out", out],
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
            cwd=out,
        )
        try:
            assert process.stdout is not None
            url = process.stdout.readline().split()[-1]
            with httpx.Client(base_url=url, timeout=30.0) as client:
                client.get("/health")
                body = {"scenario": {**ENDLESS.model_dump(mode="json"), "sim_budget": 600.0}}
                runs = [client.post("/runs", json=body).json()["id"] for _ in range(2)]
                time.sleep(0.5)  # a benchmark, not a test: let both start
                latencies = []
                for _ in range(probes):
                    start = time.perf_counter()
                    client.get("/health")
                    latencies.append(time.perf_counter() - start)
                for run_id in runs:
                    client.delete(f"/runs/{run_id}")
        finally:
            process.terminate()
            process.wait(timeout=20)
    print(f"GET /health during 2 simulations + the live robot: {_figures(latencies)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--service", action="store_true", help="also the example service")
    parser.add_argument("--probes", type=int, default=100)
    args = parser.parse_args()
    host_loop(args.reps)
    if args.service:
        service(args.probes)


if __name__ == "__main__":
    main()
