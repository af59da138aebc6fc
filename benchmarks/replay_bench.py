"""Replay speed on the acceptance recording: the navigator (and the base controller)
re-simulated against it, medians of N runs, against the original run in the same session.

    python benchmarks/replay_bench.py [--reps 7] [--baseline CHECKOUT]

The figure issue 15 asks for is the replay RTF the command prints: a user runs
``otonav replay RECORDING --node nav`` in a fresh process, and it prints the recorded sim
span over the replay's wall time (from opening the recording to the end of the comparison;
starting Python and importing otonav are before it, as for every command). So each
repetition runs the CLI as a user does, in a new process, and reads the figure it
printed ("CLI"), and the CPU time it prints beside it (what a busy machine changes
least); it also times the whole command, start to exit ("process"). Beside it, a
replay in this process, warm (``replay_recording``: what a test suite replaying a
directory of recordings pays per file), with its CPU time, which follows the machine's
load less than wall time.

``--baseline CHECKOUT``: also run another checkout's CLI (its ``.venv``) on the same
recording, interleaved with this one's (alternating which goes first), for a before/after
from one run on a shared, noisy machine.

Records the acceptance scenario once, then interleaves, per repetition: the original
run (physics + every actor + recorder) and the replays. The first repetition is a
discarded warm-up.
"""

from __future__ import annotations

import argparse
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from otonav.replay import replay_recording
from otonav.scenario import ScenarioConfig, run_scenario

NODES = ("nav", "base", "nav,base")
_PRINTED = re.compile(
    r"of\s+sim\s+time\s+in\s+([0-9.]+)\s+s\s+\(([0-9]+)x(?:;\s+CPU\s+([0-9.]+)\s+s)?\)"
)


def run_cli(
    python: Path, cwd: Path, recording: Path, nodes: str
) -> tuple[float, float | None, float]:
    """(the RTF the command printed, the CPU time s it printed (None: a version that
    does not print it), the command's wall time s, start to exit)."""
    start = time.perf_counter()
    done = subprocess.run(
        [str(python), "-m", "otonav", "replay", str(recording), "--node", nodes],
        cwd=cwd,
        capture_output=True,
        text=True,
        check=False,
    )
    wall = time.perf_counter() - start
    found = _PRINTED.search(done.stdout)
    if done.returncode != 0 or found is None:
        sys.exit(f"{python} replay --node {nodes}: exit {done.returncode}\n{done.stdout}")
    cpu = found.group(3)
    return float(found.group(2)), None if cpu is None else float(cpu), wall


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=7)
    parser.add_argument(
        "--baseline", type=Path, help="another checkout (with its .venv) to compare against"
    )
    args = parser.parse_args()
    here = Path(__file__).resolve().parent.parent
    sides = {"this": (Path(sys.executable), here)}
    if args.baseline is not None:
        base = args.baseline.resolve()
        sides = {"baseline": (base / ".venv" / "bin" / "python", base), **sides}
    rtfs: dict[str, list[float]] = {}
    walls: dict[str, list[float]] = {}
    cpus: dict[str, list[float]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        recording = Path(tmp) / "acceptance" / "recording.mcap"
        run_scenario(ScenarioConfig(), out_dir=recording.parent, plot=False)
        sim = 0.0
        for rep in range(args.reps + 1):
            verdict = run_scenario(ScenarioConfig(), out_dir=Path(tmp) / f"run{rep}", plot=False)
            if rep:
                walls.setdefault("original run", []).append(verdict.wall_time_s)
            for nodes in NODES:
                order = list(sides.items())
                if rep % 2:
                    order.reverse()
                for side, (python, cwd) in order:
                    rtf, cli_cpu, wall = run_cli(python, cwd, recording, nodes)
                    if rep:
                        rtfs.setdefault(f"CLI {side} {nodes}", []).append(rtf)
                        if cli_cpu is not None:
                            cpus.setdefault(f"CLI {side} {nodes}", []).append(cli_cpu)
                        walls.setdefault(f"process {side} {nodes}", []).append(wall)
                cpu = time.process_time()
                result = replay_recording(recording, nodes.split(","))
                cpu = time.process_time() - cpu
                assert result.byte_identical, result.first_divergence
                sim = result.sim_time_s
                if rep:
                    walls.setdefault(f"in-process {nodes}", []).append(result.wall_time_s)
                    cpus.setdefault(f"in-process {nodes}", []).append(cpu)
    base = statistics.median(walls["original run"])
    print(f"acceptance recording: {sim:.2f} s of sim time; medians of {args.reps}")
    print("replay RTF printed by 'otonav replay REC --node N' (a fresh process each):")
    for name, values in rtfs.items():
        median = statistics.median(values)
        print(
            f"  {name:<26} RTF {median:5.0f}x [{min(values):.0f}..{max(values):.0f}]"
            f"  = {sim / median * 1e3:6.1f} ms"
        )
    if args.baseline is not None:
        print("this against the baseline, median of the per-repetition ratios:")
        for nodes in NODES:
            pairs = zip(rtfs[f"CLI this {nodes}"], rtfs[f"CLI baseline {nodes}"], strict=True)
            ratios = [a / b for a, b in pairs]
            print(f"  {nodes:<26} RTF x {statistics.median(ratios):.2f}")
    print("wall times:")
    for name, values in walls.items():
        median = statistics.median(values)
        spread = f"[{min(values) * 1e3:.1f}..{max(values) * 1e3:.1f}]"
        print(
            f"  {name:<26} {median * 1e3:7.1f} ms {spread}"
            f"  RTF {sim / median:6.0f}x  original / this = {base / median:5.1f}"
        )
    for name, values in cpus.items():
        median = statistics.median(values)
        print(f"  {name:<26} CPU {median * 1e3:6.1f} ms  RTF {sim / median:6.0f}x (process time)")


if __name__ == "__main__":
    main()
