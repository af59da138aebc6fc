"""A real ROS 2 node in lockstep against a plain virtual run, interleaved in one benchmark
run (issue 37). The acceptance scenario, ``--reps`` times each, alternating:

- ``virtual``: ``otonav run`` with otonav's own navigator, no bridge;
- ``bridge``: the same with ``--ros2`` mirroring every topic and nobody on DDS, in virtual
  time (``--lockstep`` needs a node; this is what the bridge alone costs);
- ``lockstep``: ``--ros2 --lockstep /cmd_vel_nav:0.05 --set nav.planner=external`` with the
  rclpy go-to-goal node (tests/ros2/go_to_goal.py) in the ROS venv of ``--distro``
  (``make ros2-peers``), answering every 0.05 s of sim time.

Prints, per kind, the verdicts, times to goal, median run wall time and RTF (the run's own
figures from summary.json: the discovery wait before sim time starts is not in them),
median whole-process wall time, and how many lockstep recordings are byte-identical to
the first.

    python benchmarks/ros2_lockstep_bench.py [--reps 5] [--distro jazzy]
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from dds_domain import exclusive_domain  # noqa: E402

NODE = ROOT / "tests" / "ros2" / "go_to_goal.py"


def _env(domain: int) -> dict[str, str]:
    dropped = ("ROS_", "RMW_", "CYCLONEDDS", "_ROS_WHEELS", "AMENT_")
    env = {k: v for k, v in os.environ.items() if not k.startswith(dropped)}
    env.pop("LD_LIBRARY_PATH", None)
    return env | {"ROS_DOMAIN_ID": str(domain), "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}


_BRIDGE_ONLY = (
    "import dataclasses, json, pathlib, sys; from otonav.ros2 import Ros2Bridge; "
    "from otonav.stack._config import Ros2Config; "
    "from otonav.scenario import ScenarioConfig, run_scenario; "
    "from otonav.stack import StackConfig; out = pathlib.Path(sys.argv[1]); "
    "v = run_scenario(ScenarioConfig(), StackConfig(), out_dir=out, plot=False, "
    "extra_actors=(Ros2Bridge(Ros2Config(domain_id=int(sys.argv[2]))),)); "
    "(out / 'summary.json').write_text(json.dumps(dataclasses.asdict(v), default=str))"
)
"""A paced --ros2 run would measure the pacing: the bridge alone runs in virtual time."""


def _run(kind: str, out: Path, python: Path, env: dict[str, str]) -> tuple[dict[str, Any], float]:
    if kind == "bridge":
        argv = [sys.executable, "-c", _BRIDGE_ONLY, str(out), env["ROS_DOMAIN_ID"]]
    else:
        argv = [sys.executable, "-m", "otonav", "run", "--out", str(out)]
    if kind == "lockstep":
        argv += ["--ros2", "--ros2-in", "/cmd_vel_nav", "--lockstep", "/cmd_vel_nav:0.05"]
        argv += ["--set", "nav.planner=external"]
    start = time.perf_counter()
    otonav = subprocess.Popen(argv, env=env, stdout=subprocess.DEVNULL)
    node = None
    if kind == "lockstep":
        node_argv = [str(python), str(NODE), "--ros-args", "-p", "use_sim_time:=true"]
        node = subprocess.Popen(node_argv, env=env, stdout=subprocess.DEVNULL)
    otonav.wait(timeout=300)
    process_wall = time.perf_counter() - start
    if node is not None:
        node.kill()
        node.wait()
    summary: dict[str, Any] = json.loads((out / "summary.json").read_text())
    return summary, process_wall


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--distro", choices=["jazzy", "kilted"], default="jazzy")
    args = parser.parse_args()
    python = ROOT / ".venvs" / f"ros2-{args.distro}" / "bin" / "python"
    if not python.exists():
        print(f"{python} is missing: run `make ros2-peers`", file=sys.stderr)
        return 2
    kinds = ("virtual", "bridge", "lockstep")
    results: dict[str, list[tuple[dict[str, Any], float, str]]] = {k: [] for k in kinds}
    with tempfile.TemporaryDirectory() as scratch, exclusive_domain() as domain:
        env = _env(domain)
        for rep in range(args.reps):
            for kind in kinds:
                out = Path(scratch) / f"{kind}-{rep}"
                summary, process_wall = _run(kind, out, python, env)
                digest = hashlib.sha256((out / "recording.mcap").read_bytes()).hexdigest()
                results[kind].append((summary, process_wall, digest))
    print(f"acceptance scenario, {args.reps} runs each, interleaved; node: {args.distro} rclpy")
    print(f"{'kind':<10}{'verdicts':<22}{'time to goal (s)':<26}{'run wall':>10}{'RTF':>8}"
          f"{'process':>10}")  # fmt: skip
    for kind in kinds:
        rows = results[kind]
        verdicts = "".join("P" if s["passed"] else "F" for s, _w, _d in rows)
        goals = ", ".join(f"{s['time_to_goal_s']}" for s, _w, _d in rows)
        wall = statistics.median(float(s["wall_time_s"]) for s, _w, _d in rows)
        rtf = statistics.median(float(s["rtf"]) for s, _w, _d in rows)
        process = statistics.median(w for _s, w, _d in rows)
        print(f"{kind:<10}{verdicts:<22}{goals:<26}{wall:>9.3f}s{rtf:>7.1f}x{process:>9.2f}s")
    base = statistics.median(float(s["wall_time_s"]) for s, _w, _d in results["virtual"])
    for kind in ("bridge", "lockstep"):
        wall = statistics.median(float(s["wall_time_s"]) for s, _w, _d in results[kind])
        print(f"{kind} / virtual, run wall time (median): {wall / base:.2f}")
    digests = [d for _s, _w, d in results["lockstep"]]
    same = sum(d == digests[0] for d in digests)
    print(f"lockstep recordings byte-identical to the first: {same} of {len(digests)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
