"""BARN (Benchmark Autonomous Robot Navigation): its 300 static worlds with any robot
config, scored as BARN scores them, beside BARN's published DWA baseline.

    python benchmarks/barn_bench.py [--worlds 0:300:5] [--workers 2] [--set KEY=VALUE ...]
        [--config stack.yaml] [--failures DIR] [--json FILE]

Each world (``benchmarks/barn/worlds.txt``, converted by ``benchmarks/barn/convert.py``
from BARN's Gazebo worlds; MIT licence, ``benchmarks/barn/LICENSE``) becomes an otonav
scenario: an MJCF scene of its cylinders (r 0.075 m, 1 m tall), the robot at BARN's
start (-2.25, 3) facing +y, the goal 10 m ahead at (-2.25, 13), 100 s of sim time,
``arrival: enter`` with a 1 m tolerance (BARN's success: the first entry into a 1 m
circle). A run is a success when it enters that circle; a collision when the robot
centre came closer to a cylinder than the robot's footprint radius (the circle its
outline sweeps: a contact is possible, BARN ends the run on contact) or the run's
clearance was not measured; a timeout otherwise; a false ``unreachable`` when the
navigator gave up (every BARN world has a path). BARN's metric per run:
``success * t_opt / clip(t, 2 t_opt, 8 t_opt)``, ``t_opt`` = BARN's optimal path length
/ 2 m/s whatever the robot (so 0.5 at best).

Prints one table: success, collisions, timeouts, false unreachable, mean metric and mean
time of the successes; beside them BARN's DWA baseline (move_base DWA on a Jackal at
2 m/s), as its README states it (50 worlds x 10 runs) and recomputed from the results
file it ships (``benchmarks/barn/dwa_out.txt``) on the worlds of this sample that it
covers. ``--failures DIR``: each failing world is run again with its recording and its
``trajectory.png`` in DIR/world_N/.
"""

from __future__ import annotations

import argparse
import base64
import json
import math
import multiprocessing
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from otonav.scenario import run_scenario
from otonav.scenario._config import GoalSpec, ScenarioConfig, StartSpec
from otonav.stack import StackConfig
from otonav.stack._files import ConfigFileError
from otonav.stack._loading import load_stack_file
from otonav.stack._overrides import apply_overrides

HERE = Path(__file__).resolve().parent / "barn"
WORLDS = HERE / "worlds.txt"
COLUMNS, ROWS, PITCH, RADIUS, HEIGHT = 30, 64, 0.15, 0.075, 1.0
START, GOAL = (-2.25, 3.0, math.pi / 2), (-2.25, 13.0)
TOLERANCE, BUDGET, OPTIMAL_SPEED = 1.0, 100.0, 2.0
README_DWA = {"success": 0.88, "collision": 0.048, "timeout": 0.072, "metric": 0.169}
"""BARN's README, move_base DWA (50 worlds x 10 runs)."""


@dataclass(frozen=True, slots=True)
class World:
    index: int
    optimal_path_m: float
    cylinders: tuple[tuple[float, float], ...]
    """Centres, m, in BARN's world frame."""


def load_worlds(path: Path = WORLDS) -> dict[int, World]:
    worlds = {}
    for line in path.read_text().splitlines():
        if not line or line.startswith("#"):
            continue
        n, length, bits = line.split()
        flat = np.unpackbits(np.frombuffer(base64.b64decode(bits), dtype=np.uint8))
        grid = flat[: ROWS * COLUMNS].reshape(ROWS, COLUMNS).astype(bool)
        rows, cols = np.nonzero(grid)
        centres = tuple(
            (round(-RADIUS - PITCH * float(i), 6), round(RADIUS + PITCH * float(j), 6))
            for j, i in zip(rows, cols, strict=True)
        )
        worlds[int(n)] = World(int(n), float(length), centres)
    return worlds


def scene_xml(world: World) -> str:
    """The world as an MJCF scene: a floor and the cylinders (no walls: BARN has none)."""
    geoms = "\n".join(
        f'    <geom name="obstacle_{k}" type="cylinder" size="{RADIUS} {HEIGHT / 2}" '
        f'pos="{x} {y} {HEIGHT / 2}" rgba="0.15 0.38 0.72 1"/>'
        for k, (x, y) in enumerate(world.cylinders)
    )
    return f"""<mujoco model="barn_world_{world.index}">
  <compiler angle="radian"/>
  <option timestep="0.002" integrator="implicitfast"/>
  <worldbody>
    <light name="sun" pos="-2 6 8" dir="0 0 -1" directional="true"/>
    <geom name="floor" type="plane" size="12 12 0.1" pos="-2.25 6 0" solref="0.005 1"
          rgba="0.8 0.8 0.8 1"/>
{geoms}
  </worldbody>
</mujoco>
"""


def scenario(world: World, scene_dir: Path) -> ScenarioConfig:
    """The world as an otonav scenario, its scene written into ``scene_dir``."""
    scene = scene_dir / f"barn_world_{world.index}.xml"
    scene.write_text(scene_xml(world))
    return ScenarioConfig(
        name=f"barn_world_{world.index}",
        scene=str(scene),
        start=StartSpec(x=START[0], y=START[1], yaw=START[2]),
        goal=GoalSpec(x=GOAL[0], y=GOAL[1]),
        goal_tolerance=TOLERANCE,
        arrival="enter",
        sim_budget=BUDGET,
        min_clearance=0.01,  # the judge's floor; a collision is judged below, per robot
    )


@dataclass(frozen=True, slots=True)
class Run:
    world: int
    success: bool
    collision: bool
    timeout: bool
    false_unreachable: bool
    time_s: float
    metric: float
    min_clearance_m: float
    footprint_radius_m: float
    recoveries: int
    reason: str


def metric(success: bool, time_s: float, optimal_path_m: float) -> float:
    """BARN's: success * t_opt / clip(t, 2 t_opt, 8 t_opt), t_opt at 2 m/s."""
    t_opt = optimal_path_m / OPTIMAL_SPEED
    return float(success) * t_opt / float(np.clip(time_s, 2 * t_opt, 8 * t_opt))


def run_world(world: World, stack: StackConfig, out_dir: Path | None = None) -> Run:
    with tempfile.TemporaryDirectory() as tmp:
        verdict = run_scenario(
            scenario(world, Path(tmp)),
            stack,
            out_dir=out_dir,
            record=out_dir is not None,
            plot=out_dir is not None,
            wall_ceiling=1800.0,
        )
    footprint = float(verdict.robot.get("footprint_radius") or 0.0)
    clearance = verdict.min_clearance_m
    unmeasured = "clearance not measured" in verdict.reason
    collision = unmeasured or not clearance >= footprint
    success = verdict.reached and not collision
    t = verdict.time_to_goal_s if verdict.time_to_goal_s is not None else verdict.sim_time_s
    gave_up = verdict.unreachable_at_s is not None and not verdict.reached
    return Run(
        world=world.index,
        success=success,
        collision=collision,
        timeout=not success and not collision and not gave_up,
        false_unreachable=gave_up and not collision,
        time_s=round(t, 3),
        metric=round(metric(success, t, world.optimal_path_m), 4),
        min_clearance_m=round(clearance, 4),
        footprint_radius_m=footprint,
        recoveries=len(verdict.recoveries),
        reason=verdict.reason,
    )


def _task(args: tuple[World, StackConfig]) -> Run:
    return run_world(*args)


def baseline(worlds: dict[int, World], sample: list[int]) -> dict[str, float] | None:
    """BARN's DWA results file recomputed (its time and BARN's metric) on the worlds of
    ``sample`` it covers; None if it covers none."""
    rows = np.loadtxt(HERE / "dwa_out.txt", ndmin=2)
    rows = rows[np.isin(rows[:, 0].astype(int), sample)]
    if not len(rows):
        return None
    per_world: dict[int, list[tuple[float, ...]]] = {}
    for n, ok, hit, late, t, _ in rows:
        m = metric(bool(ok), t, worlds[int(n)].optimal_path_m)
        per_world.setdefault(int(n), []).append((ok, hit, late, m))
    means = np.array([np.mean(v, axis=0) for v in per_world.values()])
    return {
        "worlds": float(len(per_world)),
        "runs": float(len(rows)),
        "success": float(means[:, 0].mean()),
        "collision": float(means[:, 1].mean()),
        "timeout": float(means[:, 2].mean()),
        "metric": float(means[:, 3].mean()),
    }


def summary(runs: list[Run]) -> dict[str, float]:
    n = max(len(runs), 1)
    times = [r.time_s for r in runs if r.success]
    return {
        "worlds": float(len(runs)),
        "success": sum(r.success for r in runs) / n,
        "collision": sum(r.collision for r in runs) / n,
        "timeout": sum(r.timeout for r in runs) / n,
        "false_unreachable": sum(r.false_unreachable for r in runs) / n,
        "metric": sum(r.metric for r in runs) / n,
        "time_s": float(np.mean(times)) if times else math.nan,
        "recoveries": float(sum(r.recoveries > 0 for r in runs)),
    }


def table(ours: dict[str, float], base: dict[str, float] | None, label: str) -> str:
    def pct(v: float) -> str:
        return f"{100 * v:.1f} %"

    lines = [
        "| | worlds | success | collisions | timeouts | false unreachable | metric | time (s) |",
        "|---|---|---|---|---|---|---|---|",
        f"| {label} | {ours['worlds']:.0f} | {pct(ours['success'])} | {pct(ours['collision'])} "
        f"| {pct(ours['timeout'])} | {pct(ours['false_unreachable'])} | {ours['metric']:.3f} "
        f"| {ours['time_s']:.1f} |",
        f"| BARN DWA (README, 50 worlds x 10) | 50 | {pct(README_DWA['success'])} "
        f"| {pct(README_DWA['collision'])} | {pct(README_DWA['timeout'])} | - "
        f"| {README_DWA['metric']:.3f} | 33.5 |",
    ]
    if base is not None:
        lines.append(
            f"| BARN DWA (its results file, the {base['worlds']:.0f} of these worlds it "
            f"covers x 10) | {base['worlds']:.0f} | {pct(base['success'])} "
            f"| {pct(base['collision'])} | {pct(base['timeout'])} | - | {base['metric']:.3f} | - |"
        )
    return "\n".join(lines)


def parse_sample(text: str) -> list[int]:
    """``0:300:5`` (a range) or ``0,5,17`` (a list)."""
    if ":" in text:
        return list(range(*(int(p) for p in text.split(":"))))
    return [int(p) for p in text.split(",")]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", default="0:300:5", help="start:stop:step or a,b,c")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--config", type=Path, help="a stack config file (the robot's)")
    parser.add_argument("--set", dest="overrides", action="append", default=[])
    parser.add_argument("--label", default="otonav")
    parser.add_argument("--failures", type=Path, help="re-run failures with artifacts here")
    parser.add_argument("--json", type=Path, help="write every run's figures here")
    args = parser.parse_args()
    worlds = load_worlds()
    try:
        sample = parse_sample(args.worlds)
    except ValueError:
        print(f"--worlds {args.worlds!r}: expected start:stop:step or a,b,c", file=sys.stderr)
        return 2
    missing = [n for n in sample if n not in worlds]
    if missing:
        print(f"--worlds: {missing[:5]} not among BARN's worlds 0..299", file=sys.stderr)
        return 2
    try:
        stack = load_stack_file(args.config) if args.config else StackConfig()
        stack = apply_overrides(stack, args.overrides)
    except ConfigFileError as error:
        print(error, file=sys.stderr)
        return 2
    tasks = [(worlds[n], stack) for n in sample]
    started = time.perf_counter()
    runs: list[Run] = []
    context = multiprocessing.get_context("forkserver")
    with ProcessPoolExecutor(max_workers=args.workers, mp_context=context) as pool:
        for run in pool.map(_task, tasks, chunksize=1):
            runs.append(run)
            if len(runs) % 10 == 0:
                print(f"  {len(runs)}/{len(tasks)} worlds", file=sys.stderr, flush=True)
    ours = summary(runs)
    print(
        f"barn_bench: worlds {args.worlds} ({len(sample)}), config {args.config or 'default'}, "
        f"--set {args.overrides or 'none'}, {time.perf_counter() - started:.0f} s wall; "
        f"{ours['recoveries']:.0f} runs used recoveries"
    )
    print(table(ours, baseline(worlds, sample), args.label))
    failed = [r for r in runs if not r.success]
    for r in failed:
        kind = "collision" if r.collision else "unreachable" if r.false_unreachable else "timeout"
        print(f"  world {r.world}: {kind} ({r.reason})")
    if args.json is not None:
        args.json.write_text(json.dumps([asdict(r) for r in runs], indent=1))
    if args.failures is not None:
        for r in failed:
            out = args.failures / f"world_{r.world}"
            run_world(worlds[r.world], stack, out)
            print(f"  recorded world {r.world}: {out}/trajectory.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
