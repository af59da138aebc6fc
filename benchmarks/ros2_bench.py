"""What the ROS 2 bridge costs a run: the acceptance scenario in virtual time (so the
figure is the cost, not the pacing), interleaved in one process, ``--reps`` times each:

- ``off``: no bridge;
- ``idle``: the bridge up, nobody on DDS (a topic nobody reads is not even encoded);
- ``read``: the bridge up and a ROS 2 node in another process (tests/smoke/ros2_peer.py)
  reading rt/odom, rt/scan, rt/tf and rt/clock: every message encoded and written.

Prints median wall time and RTF of each, and the /odom latency the peer saw (DDS source
timestamp, set at the write, to its take; same host clock).

    python benchmarks/ros2_bench.py [--reps 3]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from otonav.cli._loading import load_scenario
from otonav.ros2 import Ros2Bridge
from otonav.scenario import run_scenario
from otonav.stack import StackConfig
from otonav.stack._config import Ros2Config

PEER = Path(__file__).resolve().parents[1] / "tests" / "smoke" / "ros2_peer.py"


def _run(kind: str, domain: int, env: dict[str, str], out: Path) -> tuple[float, float, int]:
    extra: tuple[Ros2Bridge, ...] = ()
    if kind != "off":
        wait = 20.0 if kind == "read" else None
        bridge = Ros2Bridge(Ros2Config(domain_id=domain, wait=wait), env=env)
        extra = (bridge,)
    start = time.perf_counter()
    verdict = run_scenario(
        load_scenario("acceptance"), StackConfig(), out_dir=out, record=False, extra_actors=extra
    )
    wall = time.perf_counter() - start
    sent = extra[0].statistics().sent if extra else 0
    if extra:
        extra[0].close()
    assert verdict.passed, verdict.reason
    return wall, verdict.sim_time_s / wall, sent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=3)
    args = parser.parse_args()
    env = {k: v for k, v in os.environ.items() if not k.startswith(("ROS_", "CYCLONEDDS"))}
    base = 150 + os.getpid() % 50
    read_domain, idle_domain = base, base + 1
    peer = subprocess.Popen(
        [sys.executable, str(PEER), str(read_domain), "99", "99", str(60 * args.reps)],
        stdout=subprocess.PIPE,
        text=True,
        env=env,
    )
    results: dict[str, list[tuple[float, float, int]]] = {"off": [], "idle": [], "read": []}
    try:
        with tempfile.TemporaryDirectory() as tmp:
            for _ in range(args.reps):
                for kind in results:
                    domain = read_domain if kind == "read" else idle_domain
                    results[kind].append(_run(kind, domain, env, Path(tmp)))
    finally:
        peer.terminate()
    out, _ = peer.communicate(timeout=30)
    lines = out.strip().splitlines()
    off = statistics.median(r[0] for r in results["off"])
    for kind, runs in results.items():
        wall = statistics.median(r[0] for r in runs)
        rtf = statistics.median(r[1] for r in runs)
        sent = statistics.median(r[2] for r in runs)
        print(
            f"{kind:>5}: wall {wall:.3f} s  RTF {rtf:.1f}x  (+{100 * (wall / off - 1):.1f}% "
            f"wall)  DDS writes {sent:.0f}"
        )
    if lines:
        print("peer:", json.dumps(json.loads(lines[-1]).get("latency_ms")))


if __name__ == "__main__":
    main()
