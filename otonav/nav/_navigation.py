"""What each step of the avoiding navigator returns (:class:`NavOutput`). Its settings,
:class:`~otonav.params.NavigationParams`, live in the numpy-free :mod:`otonav.params`;
the navigation itself is a global planner (:mod:`otonav.nav._planner`), a controller
(:mod:`otonav.nav._controller`) and a recovery ladder (:mod:`otonav.nav._recovery`), tied
by :class:`otonav.nav.Navigation` (:mod:`otonav.nav._navigate`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from otonav.nav._dwa import DwaResult

__all__ = ("NavOutput",)


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
