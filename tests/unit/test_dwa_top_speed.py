"""The DWA's choice does not depend on the unit of its top speed (issue 42): for the
same world, pose and window, ``max_v`` 0.5 and 2.0 m/s choose the same command while the
window stays below both (a robot accelerating, or driving at a speed both allow). The
score used to divide progress and speed by ``max_v``: at 2 m/s those terms shrank to a
fifth under the clearance term and a Jackal-sized robot crept at 0.017 m/s in the open."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from otonav.nav._dwa import ClearanceFn, DwaParams, dwa_step

pytestmark = pytest.mark.unit


def _field(centres: list[tuple[float, float]]) -> ClearanceFn:
    """Distance to the nearest of BARN-sized cylinders (r 0.075 m)."""
    c = np.array(centres, dtype=np.float64).reshape(-1, 2)

    def clearance(x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float32]:
        d = np.hypot(x[..., None] - c[:, 0], y[..., None] - c[:, 1]).min(axis=-1) - 0.075
        out: NDArray[np.float32] = d.astype(np.float32)
        return out

    return clearance


@settings(max_examples=300, deadline=None)
@given(
    centres=st.lists(st.tuples(st.floats(-1.5, 1.5), st.floats(0.6, 4.0)), min_size=1, max_size=25),
    v0=st.floats(0.0, 0.4),
    w0=st.floats(-1.0, 1.0),
    yaw=st.floats(0.9, 2.2),
)
def test_the_same_choice_at_half_a_metre_and_two_metres_a_second(
    centres: list[tuple[float, float]], v0: float, w0: float, yaw: float
) -> None:
    field = _field(centres)
    slow = DwaParams(max_v=0.5, max_omega=1.5, radius=0.3)
    fast = DwaParams(max_v=2.0, max_omega=1.5, radius=0.3)
    pose, target = (0.0, 0.0, yaw), (0.0, 6.0)
    a = dwa_step(pose, v0, w0, target, 10.0, field, slow)
    b = dwa_step(pose, v0, w0, target, 10.0, field, fast)
    assert (a.v, a.omega, a.best_score) == (b.v, b.omega, b.best_score)


def test_an_open_field_is_crossed_at_the_top_of_the_window() -> None:
    """Nothing near: the fastest sample of the window wins, at any top speed."""
    field = _field([(5.0, -5.0)])
    for max_v in (0.2, 0.5, 2.0):
        p = DwaParams(max_v=max_v, radius=0.3)
        result = dwa_step((0.0, 0.0, math.pi / 2), 0.1, 0.0, (0.0, 6.0), 10.0, field, p)
        assert result.v == pytest.approx(min(0.1 + p.max_accel * p.period, max_v))
