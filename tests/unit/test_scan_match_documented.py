"""scan_match's documented step acceptance (module docstring): a step is accepted when it
does not raise the cost, so at the minimum the zero step is taken, counted, and ends
the refinement (issue 24, ADR 0060 round three)."""

from __future__ import annotations

import numpy as np
import pytest

from otonav.nav.scan_map import ScanMap
from otonav.nav.scan_match import MatchParams, match_scan, refine

pytestmark = pytest.mark.unit


def _exact_room() -> tuple[ScanMap, np.ndarray]:
    """Returns at cell centres along three walls, stored from the origin: seen again from
    the origin each is its own stored return (residual exactly 0, prior exactly 0)."""
    res = 0.05
    grid = ScanMap(0.0, 0.0, half_size=2.0, resolution=res)
    k = np.arange(-20, 21)
    centre = (k + 0.5) * res
    top = np.stack((centre, np.full_like(centre, 1.025)), axis=1)
    side = np.stack((np.full_like(centre, 1.225), centre), axis=1)
    bottom = np.stack((centre[::-1], np.full_like(centre, -0.975)), axis=1)
    pts = np.concatenate((top, side, bottom))
    assert grid.insert(0.0, 0.0, pts[:, 0], pts[:, 1]) == pts.shape[0]
    return grid, pts


@pytest.mark.parametrize("prediction", [(0.0, 0.0, 0.0)])
def test_at_the_minimum_the_zero_step_is_accepted_and_counted(
    prediction: tuple[float, float, float],
) -> None:
    grid, pts = _exact_room()
    params = MatchParams(iterations=10)
    pose, steps = refine(grid, pts, prediction, prediction, params)
    assert pose == prediction
    assert steps == 1  # an equal cost is accepted: one (zero) step, then converged
    result = match_scan(grid, pts, prediction, params)
    assert result.pose == prediction
    assert result.iterations == 1
    assert result.rms == 0.0
    assert refine(grid, pts, prediction, prediction, MatchParams(iterations=0)) == (prediction, 0)
