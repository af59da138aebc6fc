"""``python -m otonav``: run the acceptance scenario headless and print the verdict.

Exit codes: 0 the scenario passed, 1 it failed, 2 usage or configuration error.
"""

from __future__ import annotations

import argparse
import sys

from otonav.scenario import ScenarioConfig, Verdict, run_scenario


def _print_verdict(verdict: Verdict) -> None:
    ttg = f"{verdict.time_to_goal_s:.2f} s" if verdict.time_to_goal_s is not None else "-"
    rows = [
        ("scenario", verdict.scenario),
        ("verdict", "PASSED" if verdict.passed else "FAILED"),
        ("why", verdict.reason),
        ("reached", "yes" if verdict.reached else "no"),
        ("time to goal", ttg),
        ("min clearance", f"{verdict.min_clearance_m:.3f} m"),
        ("final distance", f"{verdict.final_distance_m:.3f} m"),
        ("path length", f"{verdict.path_length_m:.2f} m"),
        ("sim time", f"{verdict.sim_time_s:.2f} s"),
        ("wall time", f"{verdict.wall_time_s:.3f} s"),
        ("real-time factor", f"{verdict.rtf:.0f}x"),
    ]
    width = max(len(k) for k, _ in rows)
    for key, value in rows:
        print(f"{key:<{width}}  {value}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="otonav", description=__doc__.splitlines()[0])
    parser.add_argument("command", nargs="?", default="run", choices=["run"])
    args = parser.parse_args(argv)
    del args
    verdict = run_scenario(ScenarioConfig())
    _print_verdict(verdict)
    return 0 if verdict.passed else 1


if __name__ == "__main__":
    sys.exit(main())
