"""The acceptance scenario with each robot: otonav's, the built-in burger, the example
robot from its MJCF (meshes) and its URDF, and a mesh-heavy variant of it.

    python benchmarks/robots_bench.py [--reps N]

Each run is a fresh process (``python -c``), the robots interleaved so that all of them
see the same machine load, ``--no-record`` and no plot. Prints per robot the median
wall time, real-time factor and CPU time, the model build (the world's construction,
which compiles the robot) and the ratio of its RTF to otonav's robot's in the same
run. Every run must pass; a failing run is reported, not timed.

The mesh-heavy variant is the example robot with its wheel and deck meshes re-made with
2,000 and 4,000 sides (8,000 and 16,000 triangles), written to a temporary folder.
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "my_robot"

_CHILD = """
import json, sys, time
from otonav.scenario import run_scenario
from otonav.stack import StackConfig, build_world
from otonav.stack._loading import load_stack_file
from otonav.stack._overrides import apply_overrides
kind, value = sys.argv[1], sys.argv[2]
stack = load_stack_file(value) if kind == "config" else apply_overrides(
    StackConfig(), [f"robot.model={value}"])
build = time.perf_counter()
build_world(stack).close()
build = time.perf_counter() - build
cpu = time.process_time()
v = run_scenario(stack=stack, record=False, plot=False)
cpu = time.process_time() - cpu
print(json.dumps({"passed": v.passed, "reason": v.reason, "wall": v.wall_time_s,
                  "rtf": v.rtf, "cpu": cpu, "sim": v.sim_time_s, "build": build}))
"""


def heavy_variant(folder: Path) -> Path:
    """The example robot with dense meshes, in ``folder``; returns its stack config."""
    sys.path.insert(0, str(EXAMPLE))
    import make_meshes

    for name in ("pathfinder.xml", "stack.yaml"):
        shutil.copy(EXAMPLE / name, folder / name)
    meshes = folder / "meshes"
    meshes.mkdir()
    make_meshes.write_obj(meshes / "wheel.obj", *make_meshes.prism(76.2, 12.5, 2000))
    make_meshes.write_obj(meshes / "chassis.obj", *make_meshes.prism(170.0, 50.0, 4000))
    return folder / "stack.yaml"


def run(kind: str, value: str) -> dict[str, float | bool | str]:
    out = subprocess.run(
        [sys.executable, "-c", _CHILD, kind, value],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
    )
    result: dict[str, float | bool | str] = json.loads(out.stdout.strip().splitlines()[-1])
    return result


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reps", type=int, default=5)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="otonav-robots-") as tmp:
        robots = {
            "otonav (default)": ("model", "otonav"),
            "burger": ("model", "burger"),
            "pathfinder MJCF (meshes)": ("config", str(EXAMPLE / "stack.yaml")),
            "pathfinder URDF (STL)": ("config", str(EXAMPLE / "stack_urdf.yaml")),
            "pathfinder mesh-heavy (24k tris)": ("config", str(heavy_variant(Path(tmp)))),
        }
        results: dict[str, list[dict[str, float | bool | str]]] = {name: [] for name in robots}
        for _ in range(args.reps):
            for name, (kind, value) in robots.items():
                results[name].append(run(kind, value))
    base_rtf = statistics.median(float(r["rtf"]) for r in results["otonav (default)"])
    print(f"acceptance scenario, --no-record, median of {args.reps} fresh processes, interleaved")
    print(f"{'robot':34} {'sim s':>6} {'wall s':>7} {'RTF':>6} {'CPU s':>6} {'build ms':>8} "
          f"{'RTF / otonav':>12}")  # fmt: skip
    failed = 0
    for name, runs in results.items():
        bad = [r for r in runs if not r["passed"]]
        failed += len(bad)
        good = [r for r in runs if r["passed"]] or runs
        keys = ("sim", "wall", "rtf", "cpu", "build")
        med = {k: statistics.median(float(r[k]) for r in good) for k in keys}
        print(
            f"{name:34} {med['sim']:6.2f} {med['wall']:7.3f} {med['rtf']:6.1f} "
            f"{med['cpu']:6.3f} {med['build'] * 1e3:8.1f} {med['rtf'] / base_rtf:12.2f}"
            + (f"  FAILED {len(bad)}: {bad[0]['reason']}" if bad else "")
        )
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
