"""The live progress line of ``otonav run`` on a terminal: sim time, real-time factor,
distance to goal, nav state and
the planner's reason. A callback of the judge: it only prints, so a run's
recording is the same bytes with or without it."""

from __future__ import annotations

import sys
import time
from typing import TextIO

from otonav.scenario import Judge


class ProgressLine:
    """Redraws one line at most every ``min_wall`` s of wall time (a UI may read the wall
    clock; robot actors never do)."""

    def __init__(self, stream: TextIO = sys.stderr, *, min_wall: float = 0.1) -> None:
        self.stream = stream
        self.min_wall = min_wall
        self._wall0 = time.perf_counter()
        self._last_draw = -1.0
        self.drawn = False

    def __call__(self, judge: Judge, sim: float) -> None:
        wall = time.perf_counter()
        if wall - self._last_draw < self.min_wall:
            return
        self._last_draw = wall
        elapsed = wall - self._wall0
        rtf = sim / elapsed if elapsed > 0 else 0.0
        self.stream.write(
            f"\r  sim {sim:6.2f} s | {rtf:5.0f}x real time | "
            f"{judge.distance:5.2f} m to goal | {judge.nav_state:<11} "
            f"{judge.nav_reason[:28]:<28}"
        )
        self.stream.flush()
        self.drawn = True

    def clear(self) -> None:
        if self.drawn:
            self.stream.write("\r" + " " * 110 + "\r")
            self.stream.flush()
