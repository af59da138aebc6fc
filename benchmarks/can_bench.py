"""The CAN HAL against the MuJoCo HAL: the acceptance scenario, both ways.

    python benchmarks/can_bench.py [--reps N]

Each run is a fresh process (``python -c``), the two HALs interleaved, so both see the
same machine load; with and without the recorder. Prints the median wall time and
real-time factor of each, and the ratio CAN / MuJoCo (the goal: CAN adds <= 30 %).
Every run must pass the scenario: a failing run is reported, not timed. The CPU time
of the run (``time.process_time``) is printed too: on a shared machine it moves less
than the wall time when other processes compete for the cores.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

_CHILD = """
import json, sys, tempfile, time
from pathlib import Path
from otonav.scenario import run_scenario
from otonav.stack import StackConfig
from otonav.stack.overrides import apply_overrides
kind, record = sys.argv[1], sys.argv[2] == "1"
stack = apply_overrides(StackConfig(), [f"hal.kind={kind}"])
# MuJoCo's modules are loaded by the imports above; the CAN modules (and python-can)
# load lazily when the world is built. Time them apart so both CPU figures compare.
imports = time.process_time()
if kind == "can":
    import otonav.hal.can, otonav.hal.can.tap, otonav.hal.sim
imports = time.process_time() - imports
with tempfile.TemporaryDirectory() as out:
    cpu = time.process_time()
    v = run_scenario(stack=stack, out_dir=Path(out), record=record, plot=False)
    cpu = time.process_time() - cpu
print(json.dumps({"passed": v.passed, "wall": v.wall_time_s, "cpu": cpu + imports,
                  "cpu_run": cpu, "sim": v.sim_time_s}))
"""


def run_once(kind: str, record: bool) -> dict[str, float]:
    result = subprocess.run(
        [sys.executable, "-c", _CHILD, kind, "1" if record else "0"],
        capture_output=True,
        text=True,
        check=True,
    )
    figures: dict[str, float] = json.loads(result.stdout.strip().splitlines()[-1])
    if not figures["passed"]:
        raise SystemExit(f"the acceptance scenario failed with hal.kind={kind}")
    return figures


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--reps", type=int, default=5)
    args = parser.parse_args()
    # The machine is shared: say how busy it was, so a figure can be judged.
    print("load average before: {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    with tempfile.TemporaryDirectory():
        for record in (False, True):
            walls: dict[str, list[float]] = {"mujoco": [], "can": []}
            cpus: dict[str, list[float]] = {"mujoco": [], "can": []}
            runs: dict[str, list[float]] = {"mujoco": [], "can": []}
            sim = 0.0
            for _ in range(args.reps):
                for kind in ("mujoco", "can"):
                    figures = run_once(kind, record)
                    walls[kind].append(figures["wall"])
                    cpus[kind].append(figures["cpu"])
                    runs[kind].append(figures["cpu_run"])
                    sim = figures["sim"]
            label = "with recorder" if record else "no recorder"
            med = {k: statistics.median(v) for k, v in walls.items()}
            cpu = {k: statistics.median(v) for k, v in cpus.items()}
            run = {k: statistics.median(v) for k, v in runs.items()}
            for kind in ("mujoco", "can"):
                print(
                    f"{label:14s} hal.kind={kind:6s} wall median {med[kind]:.3f} s "
                    f"(of {args.reps}: {', '.join(f'{w:.3f}' for w in walls[kind])}), "
                    f"RTF {sim / med[kind]:.0f}x, CPU median {cpu[kind]:.3f} s "
                    f"({run[kind]:.3f} s without the CAN modules' imports)"
                )
            print(
                f"{label:14s} CAN / MuJoCo: wall time {med['can'] / med['mujoco']:.2f}, "
                f"CPU time {cpu['can'] / cpu['mujoco']:.2f} "
                f"({run['can'] / run['mujoco']:.2f} without the imports)"
            )
    print("load average after:  {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
