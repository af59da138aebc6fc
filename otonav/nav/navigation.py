"""The avoiding navigator's settings (:class:`NavigationParams`, stack config ``nav.*``)
and what each step returns (:class:`NavOutput`). The navigation itself: a global planner
(:mod:`otonav.nav.planner`), a controller (:mod:`otonav.nav.controller`) and a recovery
ladder (:mod:`otonav.nav.recovery`), tied by :class:`otonav.nav.Navigation`
(:mod:`otonav.nav.navigate`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import NamedTuple

from otonav.nav.dwa import DwaParams, DwaResult

__all__ = ("NavOutput", "NavigationParams")


@dataclass(frozen=True, slots=True)
class NavigationParams:
    """Settings of :class:`Navigation` (units in the names' docs, stack config ``nav.*``).

    Attributes:
        dwa: the local planner's settings (its ``radius`` is the centre clearance).
        tolerance: goal reached within this distance, m.
        map_half_size: the map spans this far from the start in x and y, m.
        map_resolution: map cell, m.
        plan_resolution: global planner cell, m (a multiple of ``map_resolution``).
        plan_penalty: extra cost per cell near obstacles (0: shortest path).
        replan_period: blocked-path check period, s.
        lookahead: the DWA's target is at most this far along the path (at full
            speed; nearer when slower, see ``LOOKAHEAD_TIME``), m.
        max_expansions: A* gives up (no proof either way) after this many cells.
        expansions_per_tick: A* expands at most this many cells per step; a search
            that needs more goes on at the next step (the robot follows the previous
            path, or heads for the goal, meanwhile; the DWA keeps it clear).
        clear_range: before a replan, occupied cells within this distance of the laser
            that the last observed scan saw through are cleared (ADR 0026), m; 0: the
            map never clears.
        hull_margin: once the goal lies inside the convex hull of what the robot has
            observed (returns, free beam ends, laser positions), A* routes only within
            this distance of it, m (:mod:`otonav.nav.observed_hull`).
        progress_distance: progress that counts, m.
        progress_window: time to shrink the distance to go (along the path) by
            ``progress_distance``, s (:class:`~otonav.nav.recovery.ProgressChecker`).
        goal_progress_window: time to get ``progress_distance`` closer to the goal, s.
        clear_radius: the spin rung first clears the map within this distance of the
            robot, m (0: never).
        spin_angle: the look-around turn, rad.
        spin_speed: its yaw rate, rad/s.
        backup_distance: the back-up distance, m.
        backup_speed: its speed, m/s.
        follow_time: the longest boundary following, s.
        follow_speed: its speed, m/s.
        follow_distance: centre-to-boundary distance while following, m.
        approach_radius: within this distance of the goal a proportional controller
            finishes (forward or in reverse, whichever faces the goal), m.
        kp_lin: its speed per metre of distance, 1/s.
        kp_ang: its yaw rate per radian of heading error, 1/s.
    """

    dwa: DwaParams = field(default_factory=DwaParams)
    tolerance: float = 0.08
    map_half_size: float = 10.0
    map_resolution: float = 0.05
    plan_resolution: float = 0.1
    plan_penalty: float = 2.0
    replan_period: float = 0.5
    lookahead: float = 0.8
    max_expansions: int = 60_000
    expansions_per_tick: int = 600
    clear_range: float = 3.0
    hull_margin: float = 0.25
    progress_distance: float = 0.3
    progress_window: float = 3.5
    goal_progress_window: float = 30.0
    spin_angle: float = math.pi / 2
    spin_speed: float = 1.0
    backup_distance: float = 0.3
    backup_speed: float = 0.15
    follow_time: float = 5.0
    follow_speed: float = 0.2
    follow_distance: float = 0.45
    clear_radius: float = 1.0
    approach_radius: float = 0.25
    kp_lin: float = 0.8
    kp_ang: float = 2.0


class NavOutput(NamedTuple):
    """One step's command and what explains it. A named tuple, immutable like a frozen
    dataclass but made in ~0.7 us instead of ~2.7 us (one per step)."""

    v: float
    omega: float
    state: str
    """idle | driving | avoiding | blocked | recovering | unreachable | reached."""
    reason: str
    distance: float
    heading_error: float
    dwa: DwaResult | None = None
    stage: str = ""
    path_length: float = math.nan
    replans: int = 0
