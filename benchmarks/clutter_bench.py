"""The clutter curve alone (issue 30; ADR 0048, 0057, 0062): what a run costs as the world
fills with boxes, as ``otonav bench`` prints it among its other tables.

The same 17.2 s course with N boxes of 0.1 m off the robot's lane
(:mod:`otonav.bench._clutter`), each run ``otonav run --no-record`` in a fresh process,
the counts interleaved, medians of ``--reps`` runs; the ratio to the run with no boxes of
the same session, in wall and in CPU time (steadier on a shared machine); then one
cProfile run per count (what dominates). Prints the start and end time and the load
average, so figures from a loaded machine say so.

    python benchmarks/clutter_bench.py [--reps 5] [--counts 0 100 300 1000 3000]
"""

from __future__ import annotations

import argparse
import os
import time

from otonav.bench._clutter import COUNTS, clutter_curve, format_clutter


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--counts", type=int, nargs="+", default=list(COUNTS))
    parser.add_argument("--no-profile", action="store_true", help="skip the cProfile runs")
    args = parser.parse_args()
    start = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    rows = clutter_curve(tuple(args.counts), args.reps, profile=not args.no_profile)
    print(format_clutter(rows, args.reps))
    end_load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"started {start} (load average {load}), ended at load average {end_load}")


if __name__ == "__main__":
    main()
