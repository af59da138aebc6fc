"""What otonav.nav._plan_grid's docstrings promise beyond the pooled values (issue 24,
ADR 0060 round three): at stride 1 the coarse grid *is* the fine one (no copy per
replan: a caller writing into it would write into the map) and the best points are the
coarse cells given; at any other stride the result is a new array."""

from __future__ import annotations

import numpy as np
import pytest

from otonav.nav._plan_grid import best_points, pooled

pytestmark = pytest.mark.unit


def test_at_stride_one_the_fine_grid_is_returned_as_is() -> None:
    fine = np.arange(49, dtype=np.float32).reshape(7, 7)
    assert pooled(fine, 1) is fine
    rows, cols = np.array([0, 3, 6], dtype=np.intp), np.array([6, 2, 0], dtype=np.intp)
    got_r, got_c = best_points(fine, 1, rows, cols)
    assert got_r is rows
    assert got_c is cols


@pytest.mark.parametrize("stride", [2, 3])
def test_at_a_coarser_stride_the_result_shares_nothing_with_the_map(stride: int) -> None:
    fine = np.arange(49, dtype=np.float32).reshape(7, 7)
    before = fine.copy()
    coarse = pooled(fine, stride)
    assert not np.shares_memory(coarse, fine)
    coarse[...] = -1.0
    assert np.array_equal(fine, before)
