"""Replay speed on the acceptance recording: the navigator (and the base controller)
re-simulated against it, median of N runs, against the original run in the same session.

    python benchmarks/replay_bench.py [--reps 7]

Records the acceptance scenario once, then interleaves, per repetition: the original
run (physics + every actor + recorder) and a replay of each node. Prints each one's
median wall time and real-time factor (recorded sim span / wall), each replay's CPU
time (process time, what survives other jobs on the machine best), the replay's
breakdown (reading the file, everything else), and each replay's speed as a ratio to
the original run's wall time (the ratio is what survives a noisy, shared machine).
The first repetition is a discarded warm-up.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from otonav.replay import replay_recording
from otonav.replay.recording import load_recording
from otonav.scenario import ScenarioConfig, run_scenario

NODES = (("nav",), ("base",), ("nav", "base"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=7)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        recording = Path(tmp) / "acceptance" / "recording.mcap"
        run_scenario(ScenarioConfig(), out_dir=recording.parent, plot=False)
        walls: dict[str, list[float]] = {"original run": [], "read file": []}
        cpus: dict[str, list[float]] = {}
        sim = 0.0
        for rep in range(args.reps + 1):
            verdict = run_scenario(ScenarioConfig(), out_dir=Path(tmp) / f"run{rep}", plot=False)
            start = time.perf_counter()
            load_recording(recording, ["/odom", "/scan", "/goal", "/cmd_vel", "/nav/state"])
            read = time.perf_counter() - start
            if rep:
                walls["original run"].append(verdict.wall_time_s)
                walls["read file"].append(read)
            for nodes in NODES:
                cpu = time.process_time()
                result = replay_recording(recording, list(nodes))
                cpu = time.process_time() - cpu
                assert result.byte_identical, result.first_divergence
                sim = result.sim_time_s
                if rep:
                    walls.setdefault("replay " + ",".join(nodes), []).append(result.wall_time_s)
                    cpus.setdefault("replay " + ",".join(nodes), []).append(cpu)
    base = statistics.median(walls["original run"])
    print(f"acceptance recording: {sim:.2f} s of sim time; medians of {args.reps}")
    for name, values in walls.items():
        median = statistics.median(values)
        spread = f"[{min(values) * 1e3:.1f}..{max(values) * 1e3:.1f}]"
        print(
            f"{name:<18} wall {median * 1e3:7.1f} ms {spread}"
            f"  RTF {sim / median:6.0f}x  original / this = {base / median:5.1f}"
        )
    for name, values in cpus.items():
        median = statistics.median(values)
        print(f"{name:<18} CPU  {median * 1e3:7.1f} ms  RTF {sim / median:6.0f}x (process time)")


if __name__ == "__main__":
    main()
