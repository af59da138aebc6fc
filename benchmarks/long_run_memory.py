"""Memory over one long scenario run, the way ``otonav run`` makes it: the stack, the
recorder and the judge (issue 41 case 21: 1,200 s of sim grew RSS ~17 KB per sim second;
``otonav bench --long`` measures the stack and recorder without the judge).

The scenario never ends before its budget (a 1 mm goal tolerance the navigator cannot
meet: it stops 8 cm short), so the run lasts ``--sim`` seconds of sim time. The judge's
progress hook reads this process's RSS every ``--every`` sim seconds. Printed: RSS at each
checkpoint, its growth after the first minute (KB per sim second, and % of the first
minute's RSS), the peak, and the recording's size. Figures, not a test.

    python benchmarks/long_run_memory.py [--sim 1200] [--every 60]
"""

from __future__ import annotations

import argparse
import resource
import tempfile
import time
from pathlib import Path

from otonav.bench._memory import current_rss_mb
from otonav.scenario import ScenarioConfig, run_scenario
from otonav.scenario._judge import Judge


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sim", type=float, default=1200.0, help="sim seconds (1200)")
    parser.add_argument("--every", type=float, default=60.0, help="sim seconds between reads")
    args = parser.parse_args()
    scenario = ScenarioConfig.model_validate(
        {
            "name": "endless",
            "scene": "empty",
            "goal": {"x": 3.0, "y": -1.0},
            "goal_tolerance": 0.001,
            "sim_budget": args.sim,
        }
    )
    checkpoints: list[tuple[float, float, float]] = []  # sim s, wall s, RSS MB
    start = time.perf_counter()

    def progress(judge: Judge, now: float) -> None:
        if now >= (len(checkpoints) + 1) * args.every - 1e-9:
            checkpoints.append((now, time.perf_counter() - start, current_rss_mb()))

    with tempfile.TemporaryDirectory() as out:
        verdict = run_scenario(scenario, out_dir=Path(out), plot=True, progress=progress)
        size = Path(out, "recording.mcap").stat().st_size / 2**20
    print(
        f"{verdict.sim_time_s:.0f} s of sim in {verdict.wall_time_s:.1f} s wall: {verdict.reason}"
    )
    print(" sim (s)   wall (s)   RSS (MB)")
    for sim, wall, rss in checkpoints:
        print(f"{sim:8.0f} {wall:10.1f} {rss:10.1f}")
    (t0, _w0, first), (t1, _w1, last) = checkpoints[0], checkpoints[-1]
    growth = (last - first) * 1024 / (t1 - t0) if t1 > t0 else 0.0
    print(
        f"after the first {t0:.0f} s: {first:.1f} -> {last:.1f} MB, {growth:.2f} KB per sim "
        f"second ({(last - first) / first * 100:+.1f} %); peak "
        f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.1f} MB; "
        f"recording {size:.1f} MB"
    )


if __name__ == "__main__":
    main()
