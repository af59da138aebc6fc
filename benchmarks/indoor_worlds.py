"""Seeded indoor worlds (issue 24): rooms with doors, long walls, U traps, dead ends,
slaloms down to the passable limit, alcove goals and walled-in goals.

Pure Python and numpy, like :mod:`otonav.scenario._generator` (whose
:class:`~otonav.scenario._generator.GeneratedWorld` it returns): a world is drawn in a
canonical frame (start on the left, goal on the right, in the ``empty`` scene's 10 x 10
m arena), then turned by one of the square's eight symmetries drawn from the same
seed, so every direction and handedness occurs. Walls are axis-aligned boxes 0.1 m
thick.

**Labels at the robot's real limit.** A world is reachable when a disc of the
navigator's centre clearance (``nav.clearance`` = 0.35 m, :data:`PLAN_CLEARANCE`) passes
(obstacles are not grown by the footprint *and* the clearance, as the box families
are): a door of 0.78 m is open. Doors are 0.8-1.2 m; slalom gaps go down to 0.78 m, the
passable limit (2 x 0.35 + one 5 cm cell) plus 3 cm for the labelling grid's
discretisation.

**Budgets:** 3 x shortest path / ``nav.max_v`` + 10 s (:func:`budget_for` with
:data:`INDOOR`). A walled-in world's budget is the one it would have with its door
open; it passes when the navigator reports ``unreachable`` within it.

API::

    world = generate_indoor(seed, "slalom")     # -> GeneratedWorld
    INDOOR_FAMILIES                              # the family names
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from otonav.scenario._config import BoxSpec
from otonav.scenario._generator import (
    EMPTY_ARENA_HALF,
    GeneratedWorld,
    WorldParams,
    _r,
    make_world,
    plan_path,
)

__all__ = ("INDOOR", "INDOOR_FAMILIES", "PLAN_CLEARANCE", "generate_indoor")

PLAN_CLEARANCE = 0.35
"""m: the default navigator's centre clearance (max(nav.clearance, footprint radius +
padding) for the shipped robot): the disc the labels pass through gaps."""
INDOOR = WorldParams(name="indoor", budget_factor=3.0, budget_slack=10.0)
"""Budget and judge settings of every indoor family (3 x optimal + 10 s)."""
_T = 0.1  # wall thickness, m
_H = EMPTY_ARENA_HALF

Layout = tuple[list[BoxSpec], tuple[float, float, float], tuple[float, float], list[BoxSpec]]
"""(walls, start (x, y, yaw), goal, the boxes that close the goal in: walled-in only)."""


def _wall(x0: float, y0: float, x1: float, y1: float) -> BoxSpec:
    """An axis-aligned wall along the segment (thickness _T, ends extended by _T/2)."""
    if abs(x1 - x0) >= abs(y1 - y0):
        return BoxSpec(x=_r((x0 + x1) / 2), y=_r(y0), size_x=_r(abs(x1 - x0) + _T), size_y=_T)
    return BoxSpec(x=_r(x0), y=_r((y0 + y1) / 2), size_x=_T, size_y=_r(abs(y1 - y0) + _T))


def _door_wall(x: float, door_y: float, width: float) -> list[BoxSpec]:
    """A wall across the arena at ``x`` with a door of ``width`` (gap between faces)
    centred on ``door_y``."""
    lo, hi = door_y - width / 2, door_y + width / 2
    out = []
    if hi < _H:
        out.append(_wall(x, hi + _T / 2, x, _H))
    if lo > -_H:
        out.append(_wall(x, -_H, x, lo - _T / 2))
    return out


def _rooms(rng: np.random.Generator, closed: bool = False) -> Layout:
    """Three rooms in a row, one door in each partition; ``closed``: the goal's room
    has its door plugged (the labels and the budget are the open world's)."""
    a = rng.uniform(-1.8, -0.6)
    b = rng.uniform(0.8, 2.0)
    walls = _door_wall(a, rng.uniform(-3.8, 3.8), rng.uniform(0.8, 1.2))
    door_y, width = rng.uniform(-3.8, 3.8), rng.uniform(0.8, 1.2)
    walls += _door_wall(b, door_y, width)
    start = (rng.uniform(-4.2, a - 0.8), rng.uniform(-4.0, 4.0), rng.uniform(-math.pi, math.pi))
    goal = (rng.uniform(b + 0.8, 4.2), rng.uniform(-4.0, 4.0))
    plug = [BoxSpec(x=_r(b), y=_r(door_y), size_x=_T, size_y=_r(width + 2 * _T))]
    return walls, start, goal, plug if closed else []


def _walled_in(rng: np.random.Generator) -> Layout:
    return _rooms(rng, closed=True)


def _long_wall(rng: np.random.Generator) -> Layout:
    """A wall across the way with its one opening near an end; the start faces the
    wall 0.5 m from it (centre to face)."""
    width = rng.uniform(0.8, 1.2)
    walls = _door_wall(0.0, _H - 0.3 - width / 2, width)
    start = (-(0.5 + _T / 2), rng.uniform(-3.5, -1.0), 0.0)
    goal = (rng.uniform(0.8, 3.5), rng.uniform(-4.0, -1.0))
    return walls, start, goal, []


def _u_trap(rng: np.random.Generator) -> Layout:
    """A U open toward the start, on the straight line to the goal."""
    half = rng.uniform(0.7, 1.6)
    depth = rng.uniform(1.0, 2.2)
    back = rng.uniform(-0.5, 1.0)
    y0 = rng.uniform(-1.0, 1.0)
    walls = [
        _wall(back, y0 - half, back, y0 + half),
        _wall(back - depth, y0 + half, back, y0 + half),
        _wall(back - depth, y0 - half, back, y0 - half),
    ]
    start = (rng.uniform(-4.2, -3.2), y0 + rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3))
    goal = (rng.uniform(back + 1.0, 4.2), y0 + rng.uniform(-1.0, 1.0))
    return walls, start, goal, []


def _dead_end(rng: np.random.Generator) -> Layout:
    """A corridor toward the goal, closed at its far end."""
    width = rng.uniform(0.9, 1.4)
    x0, x1 = rng.uniform(-2.8, -2.0), rng.uniform(0.5, 2.0)
    y0 = rng.uniform(-1.5, 1.5)
    walls = [
        _wall(x0, y0 + width / 2 + _T / 2, x1, y0 + width / 2 + _T / 2),
        _wall(x0, y0 - width / 2 - _T / 2, x1, y0 - width / 2 - _T / 2),
        _wall(x1, y0 - width / 2 - _T / 2, x1, y0 + width / 2 + _T / 2),
    ]
    start = (rng.uniform(-4.3, x0 - 0.7), y0 + rng.uniform(-0.2, 0.2), 0.0)
    goal = (rng.uniform(x1 + 0.8, 4.3), y0 + rng.uniform(-0.5, 0.5))
    return walls, start, goal, []


def _slalom(rng: np.random.Generator) -> Layout:
    """Three or four walls across, their gaps alternating sides, down to 0.78 m."""
    count = int(rng.integers(3, 5))
    xs = np.linspace(-2.4, 2.4, count)
    side = 1.0 if rng.random() < 0.5 else -1.0
    walls: list[BoxSpec] = []
    for x in xs:
        walls += _door_wall(float(x), side * rng.uniform(2.0, 3.8), rng.uniform(0.78, 1.0))
        side = -side
    start = (rng.uniform(-4.3, -3.5), rng.uniform(-2.0, 2.0), rng.uniform(-1.0, 1.0))
    goal = (rng.uniform(3.5, 4.3), rng.uniform(-2.0, 2.0))
    return walls, start, goal, []


def _alcove(rng: np.random.Generator) -> Layout:
    """The goal in an alcove against the far wall, or in a corner of the arena."""
    width = rng.uniform(0.9, 1.3)
    depth = rng.uniform(0.7, 1.2)
    yc = rng.uniform(-3.5, 3.5)
    x_in = _H - depth
    walls = [
        _wall(x_in, yc + width / 2 + _T / 2, _H, yc + width / 2 + _T / 2),
        _wall(x_in, yc - width / 2 - _T / 2, _H, yc - width / 2 - _T / 2),
    ]
    goal = (_H - rng.uniform(0.45, min(0.6, depth - 0.1) + 1e-9), yc)
    if rng.random() < 0.3:  # a corner instead: the goal 0.45-0.6 m from two walls
        walls = [_door_wall(1.5, rng.uniform(-3.0, 3.0), rng.uniform(0.9, 1.2))[0]]
        goal = (_H - rng.uniform(0.45, 0.6), math.copysign(_H - rng.uniform(0.45, 0.6), yc))
    start = (rng.uniform(-4.3, -2.5), rng.uniform(-4.0, 4.0), rng.uniform(-math.pi, math.pi))
    return walls, start, goal, []


_FAMILIES: dict[str, Callable[[np.random.Generator], Layout]] = {
    "rooms": _rooms,
    "long_wall": _long_wall,
    "u_trap": _u_trap,
    "dead_end": _dead_end,
    "slalom": _slalom,
    "alcove": _alcove,
    "walled_in_room": _walled_in,
}
INDOOR_FAMILIES: tuple[str, ...] = tuple(_FAMILIES)
"""The indoor families, in the benchmark's order."""


def _symmetry(k: int) -> Callable[[float, float], tuple[float, float]]:
    """One of the square's eight symmetries: k // 2 quarter turns, mirrored if k odd."""

    def apply(x: float, y: float) -> tuple[float, float]:
        if k % 2:
            y = -y
        for _ in range(k // 2):
            x, y = -y, x
        return x, y

    return apply


def _turn_box(box: BoxSpec, k: int) -> BoxSpec:
    x, y = _symmetry(k)(box.x, box.y)
    sx, sy = (box.size_y, box.size_x) if (k // 2) % 2 else (box.size_x, box.size_y)
    return BoxSpec(x=_r(x), y=_r(y), size_x=sx, size_y=sy)


def _turn_yaw(yaw: float, k: int) -> float:
    if k % 2:
        yaw = -yaw
    return _r(math.remainder(yaw + (k // 2) * math.pi / 2, math.tau))


def generate_indoor(
    seed: int, family: str, max_attempts: int = INDOOR.max_attempts
) -> GeneratedWorld:
    """One world of ``family`` drawn from ``seed`` (>= 0); the same pair always gives
    the same world. Reachable families redraw (same stream) until the labelling
    finds a path, at most ``max_attempts`` times."""
    if family not in _FAMILIES:
        raise ValueError(f"unknown indoor family {family!r}; valid: {', '.join(_FAMILIES)}")
    if seed < 0:
        raise ValueError(f"generate_indoor: seed must be >= 0, got {seed}")
    rng = np.random.default_rng([seed, INDOOR_FAMILIES.index(family)])
    draw = _FAMILIES[family]
    params = replace(INDOOR, name=family, walled_in=family.startswith("walled_in"))
    attempts = 0
    while True:
        attempts += 1
        walls, start, goal, closing = draw(rng)
        k = int(rng.integers(8))
        turn = _symmetry(k)
        walls = [_turn_box(b, k) for b in walls]
        closing = [_turn_box(b, k) for b in closing]
        sx, sy = turn(start[0], start[1])
        start = (_r(sx), _r(sy), _turn_yaw(start[2], k))
        gx, gy = turn(*goal)
        goal = (_r(gx), _r(gy))
        path = plan_path(
            tuple(b.to_obstacle() for b in walls),
            start[:2],
            goal,
            PLAN_CLEARANCE,
            resolution=params.resolution,
        )
        if path is not None or attempts >= max_attempts:
            break
    reachable = path is not None and not closing
    return make_world(params, seed, (*walls, *closing), start, goal, path, reachable, attempts)
