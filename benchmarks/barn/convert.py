"""Convert BARN's 300 static Gazebo worlds to ``worlds.txt`` (one line per world).

    python benchmarks/barn/convert.py CHECKOUT [--out benchmarks/barn/worlds.txt]

CHECKOUT is a checkout of https://github.com/Daffan/the-barn-challenge (MIT licence,
``LICENSE`` beside this file). Read from it: ``jackal_helper/worlds/BARN/world_N.world``
(each obstacle a static model ``unit_cylinder_*``: a cylinder of radius 0.075 m whose
centre lies on a 0.15 m grid) and ``jackal_helper/worlds/BARN/path_files/path_N.npy``
(the path BARN's metric takes as optimal, in grid cells). Written per world: its
number, the optimal path length in m as BARN's ``run.py`` computes it (start, the path
cells mapped by its ``path_coord_to_gazebo_coord``, goal), and its cylinders as a
30 x 64 bitmap (column i: x = -0.075 - 0.15 i, row j: y = 0.075 + 0.15 j) in base64.
Nothing else of BARN's is copied; :mod:`barn_worlds` reads the file back.
"""

from __future__ import annotations

import argparse
import base64
import itertools
import math
import re
import sys
from pathlib import Path

import numpy as np

COLUMNS, ROWS, PITCH, RADIUS = 30, 64, 0.15, 0.075
START, GOAL = (-2.25, 3.0), (-2.25, 13.0)
_MODEL = re.compile(
    r"<model name=['\"]unit_cylinder_\d+['\"]>\s*<static>1</static>\s*<pose[^>]*>([^<]*)</pose>"
)
_RADIUS = re.compile(r"<radius>([^<]*)</radius>")


def cells(world: str) -> np.ndarray:
    """The world's cylinders as a (ROWS, COLUMNS) bool grid (the models' own poses, not
    the ``<state>`` block after them)."""
    body = world.split("<state")[0]
    radii = {float(r) for r in _RADIUS.findall(body)}
    if radii != {RADIUS}:
        raise ValueError(f"expected cylinders of radius {RADIUS} m, found {sorted(radii)}")
    grid = np.zeros((ROWS, COLUMNS), dtype=bool)
    for pose in _MODEL.findall(body):
        x, y = (float(v) for v in pose.split()[:2])
        i, j = (-x - RADIUS) / PITCH, (y - RADIUS) / PITCH
        if abs(i - round(i)) > 1e-6 or abs(j - round(j)) > 1e-6:
            raise ValueError(f"cylinder at ({x}, {y}) is off BARN's 0.15 m grid")
        grid[round(j), round(i)] = True
    return grid


def path_length(path: np.ndarray) -> float:
    """BARN run.py's optimal path length, m: start, each path cell, goal."""
    points = [
        START,
        *((r * PITCH - RADIUS - COLUMNS * PITCH, c * PITCH + RADIUS + 5) for r, c in path),
        GOAL,
    ]
    return sum(math.dist(a, b) for a, b in itertools.pairwise(points))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkout", type=Path)
    parser.add_argument("--out", type=Path, default=Path(__file__).with_name("worlds.txt"))
    args = parser.parse_args()
    folder = args.checkout / "jackal_helper" / "worlds" / "BARN"
    lines = [
        "# BARN (Perille, Truong, Xiao, Stone 2020), its 300 static worlds, converted by",
        "# benchmarks/barn/convert.py from github.com/Daffan/the-barn-challenge",
        "# (MIT licence, Copyright (c) 2022 Zifan Xu: LICENSE in this folder).",
        "# world  optimal_path_m  cylinders (30 x 64 bits, row-major from y = 0.075 m, base64)",
    ]
    for n in range(300):
        grid = cells((folder / f"world_{n}.world").read_text())
        bits = base64.b64encode(np.packbits(grid.ravel()).tobytes()).decode()
        length = path_length(np.load(folder / "path_files" / f"path_{n}.npy"))
        lines.append(f"{n} {length:.4f} {bits}")
    args.out.write_text("\n".join(lines) + "\n")
    print(f"wrote {args.out} (300 worlds)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
