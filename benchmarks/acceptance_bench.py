"""The acceptance scenario's figures, median of N runs, with and without the recorder.

    python benchmarks/acceptance_bench.py [--reps 5]

Prints sim time to goal, minimum clearance, wall time and real-time factor (with and
without recording, interleaved in one process; the first run of each is a discarded
warm-up), and the recorder's overhead as a ratio of medians.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
from pathlib import Path

from otonav.scenario import ScenarioConfig, Verdict, run_scenario


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=5)
    args = parser.parse_args()
    runs: dict[str, list[Verdict]] = {"recorded": [], "unrecorded": []}
    with tempfile.TemporaryDirectory() as tmp:
        for rep in range(args.reps + 1):
            for kind in runs:
                out = Path(tmp) / f"{kind}{rep}"
                verdict = run_scenario(
                    ScenarioConfig(), out_dir=out, record=kind == "recorded", plot=False
                )
                if rep > 0:
                    runs[kind].append(verdict)
    for kind, verdicts in runs.items():
        walls = [v.wall_time_s for v in verdicts]
        first = verdicts[0]
        print(
            f"{kind:<11} passed {sum(v.passed for v in verdicts)}/{len(verdicts)}  "
            f"time to goal {first.time_to_goal_s:.2f} s (sim)  "
            f"min clearance {first.min_clearance_m:.3f} m  "
            f"wall median {statistics.median(walls):.3f} s "
            f"[{min(walls):.3f}..{max(walls):.3f}]  "
            f"RTF {first.sim_time_s / statistics.median(walls):.0f}x"
        )
        assert len({(v.time_to_goal_s, v.min_clearance_m) for v in verdicts}) == 1
    ratio = statistics.median(v.wall_time_s for v in runs["recorded"]) / statistics.median(
        v.wall_time_s for v in runs["unrecorded"]
    )
    print(f"recorder overhead: recorded / unrecorded wall = {ratio:.2f}")


if __name__ == "__main__":
    main()
