"""Is MuJoCo's ray cast limited to the geoms a beam can hit? (issue 30, ADR 0048)

Measures one 360-beam scan (``mj_multiRay`` as ``MujocoInterface.read_scan`` calls it) in
the clutter bench's worlds (otonav.bench._clutter: N boxes of 0.1 m off the robot's lane),
from 13 poses along the course, and what the options MuJoCo offers would change:

- today: one call; and its two parts, the per-scan set-up (one beam) and the per-beam loop;
- boxes excluded by geom group: what a box costs a beam even when it cannot be hit;
- two passes: cutoff 2 m, then only the beams with no return within 2 m at the full range
  (exact: a return nearer than the first cutoff is one the full cast gives);
- boxes in static bodies, one per 1 m cell (MuJoCo tests a body's bounding sphere before
  its geoms): the scan, and what that layout does to a physics step;
- otonav's numpy caster for static boxes and planes (ADR 0057, ``otonav.hal._raycast``,
  what read_scan uses from ``LIDAR_CASTER_MIN_BOXES`` boxes), with MuJoCo for the beams
  it is not sure of;
- a physics step as it was and with the static geoms anchored (ADR 0062,
  ``otonav.hal.mujoco._static_sleep``: MuJoCo's sleeping skips them in mj_kinematics).

Each figure is a median of CPU time (this machine is shared), us per scan or per step; every
variant's ranges and geom ids are compared with today's ("same" or "DIFFERENT").
This script measures MuJoCo itself, so it imports mujoco (otonav's modules do not).

    python benchmarks/ray_bench.py [--counts 0 300 1000 3000]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from collections.abc import Callable
from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from otonav.bench._clutter import clutter_scenario
from otonav.hal._raycast import StaticRayCaster
from otonav.hal._types import LidarSpec
from otonav.hal.mujoco import _lidar as lidar
from otonav.hal.mujoco import _static_sleep as static_sleep
from otonav.hal.mujoco import scene_path

BEAMS = 360
RANGE = 8.0
GROUPS = np.array([1, 0, 1, 0, 0, 0], dtype=np.uint8)  # as read_scan: groups 0 and 2
HIDDEN = 5  # a group no beam is cast against
_ANGLES = -math.pi + 2 * math.pi / BEAMS * np.arange(BEAMS)
VEC = np.stack((np.cos(_ANGLES), np.sin(_ANGLES), np.zeros(BEAMS)), axis=1)
POSES = [np.array([x, 0.0, 0.15]) for x in np.linspace(-3.0, 3.0, 13)]


def world(boxes: int, cell: float | None, *, anchor: bool = False) -> tuple[Any, Any]:
    """The empty scene with the clutter course's boxes, in the world body (as the HAL
    builds it) or in one static body per ``cell`` square; ``anchor``: with the sleeping
    anchor the HAL adds from ``MIN_STATIC_GEOMS`` static geoms (ADR 0062)."""
    with scene_path("empty") as path:
        spec = mujoco.MjSpec.from_file(str(path))
    bodies: dict[tuple[int, int], Any] = {}
    for i, b in enumerate(clutter_scenario(boxes).obstacles):
        box = b.to_obstacle()
        parent = spec.worldbody
        if cell is not None:
            key = (math.floor(box.x / cell), math.floor(box.y / cell))
            if key not in bodies:
                bodies[key] = spec.worldbody.add_body(name=f"cell_{len(bodies)}")
            parent = bodies[key]
        parent.add_geom(
            name=f"obstacle_extra_{i}",
            type=mujoco.mjtGeom.mjGEOM_BOX,
            size=[box.half_x, box.half_y, 0.25],
            pos=[box.x, box.y, 0.25],
            quat=[math.cos(box.yaw / 2), 0.0, 0.0, math.sin(box.yaw / 2)],
        )
    if anchor:
        static_sleep.anchor_static_geoms(spec)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    return model, data


Scan = tuple[NDArray[np.int32], NDArray[np.float64]]
"""Per beam: the geom hit (-1: none) and its distance."""


def cast(m: Any, d: Any, pnt: NDArray[np.float64], rows: Any, cutoff: float) -> Scan:
    vec = np.ascontiguousarray(VEC[rows])
    geom = np.full(len(vec), -1, np.int32)
    dist = np.full(len(vec), -1.0)
    chassis = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "chassis")
    mujoco.mj_multiRay(
        m, d, pnt, vec.reshape(-1), GROUPS, 1, chassis, geom, dist, None, len(vec), cutoff
    )
    return geom, dist


def today(m: Any, d: Any, pnt: NDArray[np.float64]) -> Scan:
    return cast(m, d, pnt, slice(None), RANGE)


def two_passes(m: Any, d: Any, pnt: NDArray[np.float64], first: float = 2.0) -> Scan:
    geom, dist = cast(m, d, pnt, slice(None), first)
    far = np.flatnonzero((geom < 0) | (dist > first - 1e-6))
    if len(far):
        geom[far], dist[far] = cast(m, d, pnt, far, RANGE)
    return geom, dist


def numpy_caster(m: Any, d: Any) -> StaticRayCaster:
    """The caster read_scan builds for this world (whatever its box count)."""
    threshold = lidar.MIN_STATIC_BOXES
    lidar.MIN_STATIC_BOXES = 0  # type: ignore[misc]
    try:
        caster, _moving = lidar.ray_caster(m, d, LidarSpec(BEAMS, range_max=RANGE), -1)
    finally:
        lidar.MIN_STATIC_BOXES = threshold  # type: ignore[misc]
    assert caster is not None
    return caster


def with_caster(caster: StaticRayCaster) -> Callable[[Any, Any, NDArray[np.float64]], Scan]:
    """A scan as read_scan makes it: the caster, then MuJoCo for the beams it is unsure of."""

    def scan(m: Any, d: Any, pnt: NDArray[np.float64]) -> Scan:
        geom = np.full(BEAMS, -1, np.int32)
        dist = np.full(BEAMS, -1.0)
        unsure = caster.cast(pnt, np.eye(3), VEC, geom, dist)
        if unsure.any():
            rows = np.flatnonzero(unsure)
            geom[rows], dist[rows] = cast(m, d, pnt, rows, RANGE)
        return geom, dist

    return scan


def cpu_us(f: Callable[[], object], inner: int) -> float:
    laps = []
    for _ in range(7):
        t = time.process_time()
        for _ in range(inner):
            f()
        laps.append((time.process_time() - t) / inner)
    return statistics.median(laps) * 1e6


def per_scan(m: Any, d: Any, how: Callable[[Any, Any, NDArray[np.float64]], Scan]) -> float:
    return cpu_us(lambda: [how(m, d, p) for p in POSES], 3) / len(POSES)


def same(a: list[Scan], b: list[Scan], ma: Any, mb: Any) -> str:
    """Same distances and same geoms hit (by name: the layouts number geoms differently)."""

    def names(m: Any, geoms: NDArray[np.int32]) -> list[str]:
        return [m.geom(int(g)).name if g >= 0 else "" for g in geoms]

    pairs = zip(a, b, strict=True)
    equal = all(np.array_equal(x[1], y[1]) and names(ma, x[0]) == names(mb, y[0]) for x, y in pairs)
    return "same" if equal else "DIFFERENT"


def step_us(m: Any, d: Any) -> float:
    mujoco.mj_step(m, d, nstep=50)
    return cpu_us(lambda: mujoco.mj_step(m, d, nstep=10), 30) / 10


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--counts", type=int, nargs="+", default=[0, 300, 1000, 3000])
    args = parser.parse_args()
    print(f"one {BEAMS}-beam scan, CPU us (median), {len(POSES)} poses along the clutter course")
    print(
        f"{'boxes':>6}{'today':>8}{'set-up':>8}{'/beam':>7}{'hidden':>8}{'2 pass':>8}"
        f"{'cells':>8}{'numpy':>8}   {'step':>6}{'step, cells':>12}{'anchored':>10}"
    )
    for n in args.counts:
        m, d = world(n, None)
        ref = [today(m, d, p) for p in POSES]
        t_today = per_scan(m, d, today)

        def one_beam(m: Any = m, d: Any = d) -> Scan:
            return cast(m, d, POSES[6], slice(0, 1), RANGE)

        setup = cpu_us(one_beam, 100)
        per_beam = (t_today - setup) / (BEAMS - 1)
        boxes = np.array(
            [g for g in range(m.ngeom) if m.geom(g).name.startswith("obstacle_extra_")], int
        )
        groups = m.geom_group[boxes].copy()
        m.geom_group[boxes] = HIDDEN
        t_hidden = per_scan(m, d, today)
        m.geom_group[boxes] = groups
        t_two = per_scan(m, d, two_passes)
        two_same = same(ref, [two_passes(m, d, p) for p in POSES], m, m)
        t_step = step_us(m, d)
        mc, dc = world(n, 1.0)
        t_cells = per_scan(mc, dc, today)
        cells_same = same(ref, [today(mc, dc, p) for p in POSES], m, mc)
        t_step_cells = step_us(mc, dc)
        ma, da = world(n, None, anchor=True)
        t_step_anchored = step_us(ma, da)
        numpy_scan = with_caster(numpy_caster(m, d))
        numpy_scan(m, d, POSES[0])  # its first scan has no previous one to start from
        t_numpy = per_scan(m, d, numpy_scan)
        numpy_same = same(ref, [numpy_scan(m, d, p) for p in POSES], m, m)
        print(
            f"{n:>6}{t_today:>8.0f}{setup:>8.0f}{per_beam:>7.1f}{t_hidden:>8.0f}"
            f"{t_two:>8.0f}{t_cells:>8.0f}{t_numpy:>8.0f}   {t_step:>6.1f}{t_step_cells:>12.1f}"
            f"{t_step_anchored:>10.1f}"
            f"   (2 pass {two_same}, cells {cells_same}, numpy {numpy_same})"
        )
    print(
        "hidden: boxes in a group no beam is cast against (what a box costs a beam that "
        "cannot hit it); cells: the boxes in one static body per 1 m square; numpy: "
        "otonav's caster for static boxes and planes (ADR 0057); anchored: a step with the "
        "static geoms anchored (ADR 0062; from MIN_STATIC_GEOMS static geoms)"
    )


if __name__ == "__main__":
    main()
