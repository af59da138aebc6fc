"""The localization math (otonav.nav._scan_map, otonav.nav._scan_match): a known transform
is recovered from synthetic scans of a known world, a corridor's unconstrained length
stays at the prediction, an empty or foreign map is not trusted, and the map's fields
hold what they say."""

from __future__ import annotations

import math

import numpy as np
import pytest
from synthetic_scans import CORRIDOR, ROOM, Segment, box, circle, scan

from otonav.nav._scan_map import CLAMP, HIT, MISS, ScanMap, normals
from otonav.nav._scan_match import (
    MatchParams,
    compose,
    correlative_search,
    inverse,
    match_scan,
    refine,
    transform,
)

pytestmark = pytest.mark.unit


def mapped(world: list[Segment], *poses: tuple[float, float, float], half: float = 8.0) -> ScanMap:
    grid = ScanMap(0.0, 0.0, half_size=half, resolution=0.05, max_distance=0.3)
    for pose in poses:
        x, y = transform(pose, scan(world, pose))
        grid.insert(pose[0], pose[1], x, y)
    return grid


def error(a: tuple[float, float, float], b: tuple[float, float, float]) -> tuple[float, float]:
    return math.hypot(a[0] - b[0], a[1] - b[1]), abs(math.remainder(a[2] - b[2], math.tau))


# -- poses ------------------------------------------------------------------------------


@pytest.mark.parametrize("a", [(0.0, 0.0, 0.0), (1.5, -2.0, 0.7), (-3.0, 0.5, -2.9)])
def test_compose_with_the_inverse_is_the_identity(a: tuple[float, float, float]) -> None:
    for pose in (compose(a, inverse(a)), compose(inverse(a), a)):
        assert pose == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)


def test_compose_moves_then_turns_in_the_first_frame() -> None:
    assert compose((1.0, 2.0, math.pi / 2), (1.0, 0.0, 0.5)) == pytest.approx(
        (1.0, 3.0, math.pi / 2 + 0.5)
    )
    assert compose((0.0, 0.0, 3.0), (0.0, 0.0, 0.5))[2] == pytest.approx(3.5 - math.tau)


def test_transform_agrees_with_compose() -> None:
    pose = (0.3, -1.2, 2.1)
    pts = np.array([[1.0, 0.0], [0.5, -2.0], [0.0, 0.0]])
    x, y = transform(pose, pts)
    for i in range(3):
        expected = compose(pose, (pts[i, 0], pts[i, 1], 0.0))
        assert (x[i], y[i]) == pytest.approx(expected[:2])


# -- the map ----------------------------------------------------------------------------


def test_the_distance_field_is_the_distance_to_the_stored_return_capped() -> None:
    grid = ScanMap(0.0, 0.0, half_size=2.0, resolution=0.1, max_distance=0.35)
    assert grid.insert(-1.0, 0.0, np.array([0.03]), np.array([0.01])) == 1
    # cell centres at 0.05 + 0.1 k: (0.05, 0.05) is 0.0283 from the return
    d = grid.nearest(np.array([0.05, 0.25, 0.05, 1.0]), np.array([0.05, 0.05, -0.15, 1.0]))
    assert d == pytest.approx(
        [math.hypot(0.02, 0.04), math.hypot(0.22, 0.04), math.hypot(0.02, 0.16), 0.35]
    )
    assert grid.cells == 1
    # the same cell again: no new cell, the field unchanged
    assert grid.insert(-1.0, 0.0, np.array([0.07]), np.array([0.08])) == 0
    assert grid.nearest(np.array([0.05]), np.array([0.05]))[0] == pytest.approx(
        math.hypot(0.02, 0.04)
    )


def test_correspond_gives_the_nearest_stored_return_and_none_beyond_the_cap() -> None:
    grid = ScanMap(0.0, 0.0, half_size=2.0, resolution=0.1, max_distance=0.3)
    grid.insert(-1.0, 0.0, np.array([0.02, 0.51]), np.array([0.0, 0.0]))
    qx, qy, _, _, found = grid.correspond(np.array([0.1, 0.4, 1.5]), np.array([0.0, 0.0, 0.0]))
    assert found.tolist() == [True, True, False]
    assert qx[:2].tolist() == [0.02, 0.51]
    assert qy[:2].tolist() == [0.0, 0.0]


def test_normals_of_a_straight_wall_are_perpendicular_and_an_edge_has_none() -> None:
    x = np.array([0.0, 0.05, 0.1, 0.15, 2.0])
    y = np.array([1.0, 1.0, 1.0, 1.0, 1.0])
    nx, ny = normals(x, y, 0.05)
    assert nx[1:3] == pytest.approx([0.0, 0.0])
    assert np.abs(ny[1:3]) == pytest.approx([1.0, 1.0])
    # ends, and a return whose neighbour is 1.85 m away, have none
    assert (nx[[0, 3, 4]] == 0).all()
    assert (ny[[0, 3, 4]] == 0).all()


def test_normals_of_a_corner_are_left_out() -> None:
    x = np.array([0.0, 0.1, 0.1])
    y = np.array([0.0, 0.0, 0.1])
    nx, ny = normals(x, y, 0.05)
    assert nx[1] == 0.0
    assert ny[1] == 0.0


def test_occupancy_hits_misses_and_unknown() -> None:
    grid = ScanMap(0.0, 0.0, half_size=1.0, resolution=0.1, max_distance=0.3)
    grid.insert(-0.95, 0.05, np.array([0.55]), np.array([0.05]))
    row0, col0, height, width, cells = grid.occupancy()
    # the beam's row, from the sensor's cell (col 0) to the return's (col 15)
    assert (row0, col0, height, width) == (10, 0, 1, 16)
    expected_hit = round(100 / (1 + math.exp(-HIT)))
    expected_miss = round(100 / (1 + math.exp(MISS)))
    assert cells[-1] == expected_hit
    assert (cells[:-1] == expected_miss).all()
    for _ in range(20):
        grid.insert(-0.95, 0.05, np.array([0.55]), np.array([0.05]))
    odds = grid.log_odds[10]
    assert odds[15] == pytest.approx(CLAMP)
    assert odds[0] == pytest.approx(-CLAMP)
    assert grid.occupancy()[4][-1] == round(100 / (1 + math.exp(-CLAMP)))


def test_an_empty_map_knows_nothing() -> None:
    grid = ScanMap(0.0, 0.0, half_size=1.0, resolution=0.1)
    assert grid.occupancy()[:4] == (0, 0, 0, 0)
    assert grid.nearest(np.array([0.0]), np.array([0.0]))[0] == grid.max_distance


@pytest.mark.parametrize(
    ("name", "kwargs"),
    [("half_size", {"half_size": 0.0}), ("resolution", {"resolution": math.nan})],
)
def test_bad_map_settings_are_refused(name: str, kwargs: dict[str, float]) -> None:
    with pytest.raises(ValueError, match=name):
        ScanMap(0.0, 0.0, **kwargs)


# -- matching ---------------------------------------------------------------------------

TRUE = (0.3, -0.2, 0.2)


@pytest.mark.parametrize(
    "offset",
    [
        (0.0, 0.0, 0.0),
        (0.07, -0.04, 0.03),
        (-0.09, 0.08, -0.05),
        (0.1, 0.1, 0.06),
        (0.02, 0.0, -0.01),
    ],
)
def test_a_known_transform_is_recovered(offset: tuple[float, float, float]) -> None:
    grid = mapped(ROOM, (0.0, 0.0, 0.0))
    points = scan(ROOM, TRUE)
    prediction = (TRUE[0] + offset[0], TRUE[1] + offset[1], TRUE[2] + offset[2])
    result = match_scan(grid, points, prediction, MatchParams())
    assert result.ok
    assert result.inliers > 0.9
    distance, yaw = error(result.pose, TRUE)
    assert distance < 0.01
    assert yaw < 0.005


def test_the_match_is_deterministic() -> None:
    grid = mapped(ROOM, (0.0, 0.0, 0.0))
    points = scan(ROOM, TRUE)
    prediction = (0.37, -0.24, 0.23)
    assert match_scan(grid, points, prediction, MatchParams()) == match_scan(
        grid, points, prediction, MatchParams()
    )


def test_a_scan_from_the_mapped_pose_matches_exactly() -> None:
    pose = (0.5, 0.5, 0.3)
    grid = mapped(ROOM, pose)
    result = match_scan(grid, scan(ROOM, pose), (0.55, 0.47, 0.33), MatchParams())
    distance, yaw = error(result.pose, pose)
    # a cell keeps its first return only: the others match it along its normal
    assert distance < 3e-3
    assert yaw < 1e-3
    assert result.rms < 0.01


def test_the_correlative_search_lands_within_one_step_of_the_truth() -> None:
    grid = mapped(ROOM, (0.0, 0.0, 0.0))
    params = MatchParams()
    prediction = (TRUE[0] + 0.1, TRUE[1] - 0.1, TRUE[2] + 0.06)
    best, cost = correlative_search(grid, scan(ROOM, TRUE), prediction, params)
    distance, yaw = error(best, TRUE)
    assert distance <= math.sqrt(2) * params.linear_step / 2 + 0.01
    assert yaw <= params.angular_step / 2 + 1e-9
    # the points fit there: a mean squared distance of a few cm^2 (cell centres)
    assert cost / scan(ROOM, TRUE).shape[0] < 0.01
    # it improved on the prediction's own cost
    _, at_prediction = correlative_search(
        grid,
        scan(ROOM, TRUE),
        prediction,
        MatchParams(linear_window=0.0, angular_window=0.0),
    )
    assert cost < at_prediction


def test_a_corridor_keeps_its_length_from_the_prediction_and_fixes_the_rest() -> None:
    grid = mapped(CORRIDOR, (0.0, 0.0, 0.0), half=10.0)
    truth = (0.5, 0.1, 0.05)
    prediction = (0.65, 0.15, 0.03)  # 15 cm too far along the corridor, 5 cm across
    result = match_scan(grid, scan(CORRIDOR, truth), prediction, MatchParams())
    assert result.ok
    x, y, yaw = result.pose
    assert y == pytest.approx(truth[1], abs=0.005)  # across: measured
    assert yaw == pytest.approx(truth[2], abs=0.003)
    assert x == pytest.approx(prediction[0], abs=0.01)  # along: the prediction, no drift


def test_refinement_without_the_prior_may_slide_along_a_corridor_but_not_with_it() -> None:
    grid = mapped(CORRIDOR, (0.0, 0.0, 0.0), half=10.0)
    truth = (0.5, 0.0, 0.0)
    prediction = (0.62, 0.04, 0.0)
    pose, steps = refine(grid, scan(CORRIDOR, truth), prediction, prediction, MatchParams())
    assert steps >= 1
    assert pose[0] == pytest.approx(prediction[0], abs=0.005)
    assert pose[1] == pytest.approx(0.0, abs=0.005)


def test_an_empty_map_is_not_trusted() -> None:
    grid = ScanMap(0.0, 0.0, half_size=5.0)
    prediction = (1.0, 2.0, 0.3)
    result = match_scan(grid, scan(ROOM, TRUE), prediction, MatchParams())
    assert not result.ok
    assert result.pose == prediction


def test_a_scan_of_another_world_is_not_trusted() -> None:
    grid = mapped(box(0, 0, 5, 5), (0.0, 0.0, 0.0))
    elsewhere = [(-1.5, -3.0, -1.5, 3.0), (1.7, -3.0, 1.7, 3.0)]  # nowhere near the walls
    prediction = (0.0, 0.0, 0.0)
    result = match_scan(grid, scan(elsewhere, prediction), prediction, MatchParams())
    assert not result.ok
    assert result.inliers < MatchParams().min_inliers
    assert result.pose == prediction


def test_no_points_is_not_trusted() -> None:
    grid = mapped(ROOM, (0.0, 0.0, 0.0))
    result = match_scan(grid, np.empty((0, 2)), (0.1, 0.0, 0.0), MatchParams())
    assert not result.ok
    assert result.pose == (0.1, 0.0, 0.0)
    assert result.inliers == 0.0
    assert result.iterations == 0
    assert math.isnan(result.rms)


def test_with_no_inliers_required_any_match_is_trusted() -> None:
    grid = mapped(box(0, 0, 5, 5), (0.0, 0.0, 0.0))
    elsewhere = [(-1.5, -3.0, -1.5, 3.0), (1.7, -3.0, 1.7, 3.0)]
    result = match_scan(
        grid, scan(elsewhere, (0.0, 0.0, 0.0)), (0.0, 0.0, 0.0), MatchParams(min_inliers=0.0)
    )
    assert result.ok
    assert result.inliers == 0.0


def test_what_a_round_room_cannot_tell_stays_at_the_prediction() -> None:
    # from the centre of a round room: position measured, heading not
    room = circle(3.0)
    grid = mapped(room, (0.0, 0.0, 0.0))
    prediction = (0.06, -0.04, 0.3)
    result = match_scan(grid, scan(room, (0.0, 0.0, 0.0)), prediction, MatchParams())
    assert result.ok
    assert result.pose[0] == pytest.approx(0.0, abs=0.005)
    assert result.pose[1] == pytest.approx(0.0, abs=0.005)
    assert result.pose[2] == pytest.approx(0.3, abs=0.005)


def test_refinement_converges_in_a_few_steps() -> None:
    grid = mapped(ROOM, (0.0, 0.0, 0.0))
    truth = (0.3, -0.2, 1.2)  # turned well away from the map's axes
    for offset in ((0.0, 0.0, 0.03), (0.03, -0.02, 0.0), (0.02, 0.02, -0.02)):
        prediction = (truth[0] + offset[0], truth[1] + offset[1], truth[2] + offset[2])
        pose, steps = refine(grid, scan(ROOM, truth), prediction, prediction, MatchParams())
        assert error(pose, truth)[0] < 0.002
        assert error(pose, truth)[1] < 5e-4
        assert 1 <= steps <= 4


def test_no_refinement_steps_leave_the_start() -> None:
    grid = mapped(ROOM, (0.0, 0.0, 0.0))
    start = (TRUE[0] + 0.03, TRUE[1], TRUE[2])
    pose, steps = refine(grid, scan(ROOM, TRUE), start, start, MatchParams(iterations=0))
    assert (pose, steps) == (start, 0)


@pytest.mark.parametrize(
    "params",
    [
        {"iterations": 0},
        {"min_inliers": 0.0},
        {"min_inliers": 1.0},
        {"linear_window": 0.0, "angular_window": 0.0, "prior": 0.0, "yaw_scale": 0.0},
    ],
)
def test_boundary_settings_are_accepted(params: dict[str, float]) -> None:
    MatchParams(**params)  # type: ignore[arg-type]


def test_refinement_recovers_what_the_search_window_does_not_cover() -> None:
    grid = mapped(ROOM, (0.0, 0.0, 0.0))
    prediction = (TRUE[0] + 0.04, TRUE[1] - 0.03, TRUE[2] + 0.02)
    result = match_scan(
        grid, scan(ROOM, TRUE), prediction, MatchParams(linear_window=0.0, angular_window=0.0)
    )
    assert error(result.pose, TRUE)[0] < 0.01
    assert result.iterations >= 1


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("linear_step", 0.0),
        ("angular_step", -1.0),
        ("max_distance", math.inf),
        ("prior", -1.0),
        ("min_inliers", 1.5),
        ("iterations", -1),
    ],
)
def test_bad_match_settings_are_refused(field: str, value: float) -> None:
    with pytest.raises(ValueError, match=field):
        MatchParams(**{field: value})  # type: ignore[arg-type]


def fence() -> list[Segment]:
    """Two long walls and, between them, a row of posts every 0.4 m (-2.8 to 2.8 m):
    along the row, only the posts (and where the row ends) say where the robot is."""
    world: list[Segment] = [(-6, -1.5, 6, -1.5), (-6, 1.5, 6, 1.5)]
    for k in range(-7, 8):
        world += box(0.4 * k, 0.8, 0.05, 0.05)
    return world


@pytest.mark.parametrize("along", [0.25, -0.25])
def test_the_search_finds_the_right_post_where_refinement_alone_takes_the_wrong_one(
    along: float,
) -> None:
    world = fence()
    grid = mapped(world, (0.0, 0.0, 0.0))
    params = MatchParams(linear_window=0.3)
    points = scan(world, (0.0, 0.0, 0.0))
    prediction = (along, 0.02, 0.01)  # nearer the next post than the right one
    alone, _ = refine(grid, points, prediction, prediction, params)
    assert abs(alone[0]) > 0.2  # Gauss-Newton from the prediction: not the right post
    result = match_scan(grid, points, prediction, params)
    assert result.ok
    assert abs(result.pose[0]) < 0.03
    assert abs(result.pose[1]) < 0.005


def test_the_search_tries_the_prediction_first_then_outward() -> None:
    from otonav.nav._scan_match import _offsets

    assert _offsets(0.1, 0.05).tolist() == pytest.approx([0.0, 0.05, -0.05, 0.1, -0.1])
    assert _offsets(0.0, 0.05).tolist() == [0.0]
    assert _offsets(0.12, 0.05).tolist() == pytest.approx([0.0, 0.05, -0.05, 0.1, -0.1])


def test_a_heavy_prior_keeps_the_search_at_the_prediction() -> None:
    grid = mapped(ROOM, (0.0, 0.0, 0.0))
    prediction = (TRUE[0] + 0.1, TRUE[1] - 0.05, TRUE[2] + 0.04)
    points = scan(ROOM, TRUE)
    best, cost = correlative_search(grid, points, prediction, MatchParams(prior=1e6))
    assert best == pytest.approx(prediction)
    light, _ = correlative_search(grid, points, prediction, MatchParams(prior=1e-3))
    assert error(light, TRUE)[0] < 0.05
    # the prior's share of the cost is zero at the prediction
    assert cost == pytest.approx(
        correlative_search(
            grid, points, prediction, MatchParams(linear_window=0.0, angular_window=0.0)
        )[1]
    )


def test_a_beam_along_a_column_frees_that_column_only() -> None:
    grid = ScanMap(0.0, 0.0, half_size=1.0, resolution=0.1, max_distance=0.3)
    grid.insert(0.35, -0.85, np.array([0.35]), np.array([0.65]))
    known_rows, known_cols = np.nonzero(grid.known)
    assert set(known_cols.tolist()) == {13}
    assert sorted(known_rows.tolist()) == list(range(1, 17))  # sensor's cell to return's
    assert grid.log_odds[16, 13] > 0.0  # the return's cell: occupied
    assert (grid.log_odds[1:16, 13] < 0.0).all()  # the cells before it: free


def test_a_diagonal_beam_frees_the_cells_it_crosses_and_not_its_return() -> None:
    grid = ScanMap(0.0, 0.0, half_size=1.0, resolution=0.1, max_distance=0.3)
    grid.insert(-0.75, -0.75, np.array([0.45]), np.array([0.45]))
    free = {(int(r), int(c)) for r, c in zip(*np.nonzero(grid.log_odds < 0.0), strict=True)}
    assert {(k, k) for k in range(2, 14)} <= free  # the diagonal's cells
    assert all(abs(r - c) <= 1 for r, c in free)  # nothing off the line
    assert grid.log_odds[14, 14] > 0.0
    assert (14, 14) not in free
    # a return late in its cell: the last sample, one cell short along the diagonal,
    # falls in the same cell, and must not count as a miss there
    late = ScanMap(0.0, 0.0, half_size=1.0, resolution=0.1, max_distance=0.3)
    late.insert(-0.75, -0.75, np.array([0.099]), np.array([0.099]))
    assert late.log_odds[10, 10] == pytest.approx(HIT)


def test_a_beam_leaving_the_map_marks_only_what_is_inside() -> None:
    grid = ScanMap(0.0, 0.0, half_size=1.0, resolution=0.1, max_distance=0.3)
    # the return just past the edge (column 20 of 0-19), then one far beyond
    assert grid.insert(0.05, 0.05, np.array([1.05]), np.array([0.05])) == 0
    assert grid.insert(0.05, 0.05, np.array([3.0]), np.array([0.05])) == 0
    assert grid.cells == 0
    rows, cols = np.nonzero(grid.known)
    assert rows.tolist() == [10] * 10
    assert cols.tolist() == list(range(10, 20))
    grid.insert(-0.05, 0.05, np.array([-3.0]), np.array([0.05]))  # and the other way
    assert np.nonzero(grid.known[10])[0].tolist() == list(range(20))
    assert grid.known.sum() == 20


def test_normals_need_neighbours_within_four_cells() -> None:
    x = np.array([0.0, 0.19, 0.38, 0.6, 0.82])
    y = np.zeros(5)
    nx, ny = normals(x, y, 0.05)  # 0.19 m apart: one surface; 0.22 m: not
    assert abs(ny[1]) == pytest.approx(1.0)
    assert ny[2] == 0.0
    assert ny[3] == 0.0
    assert nx.tolist() == [0.0] * 5


def test_the_map_stores_more_returns_than_its_first_allocation() -> None:
    grid = ScanMap(0.0, 0.0, half_size=5.0, resolution=0.05, max_distance=0.3)
    rows = np.arange(1.0, 4.6, 0.5)  # 8 walls of 160 cells
    x = np.tile(np.linspace(-4.0, 4.0, 400), rows.shape[0])
    y = np.repeat(rows, 400)
    assert grid.insert(0.0, 0.0, x, y) > 1024
    qx, qy, _, ny, found = grid.correspond(np.array([-3.88, 3.88]), np.array([1.02, 1.02]))
    assert found.all()
    assert qx == pytest.approx([-3.88, 3.88], abs=0.05)  # the first return in its cell
    assert qy == pytest.approx([1.0, 1.0])
    assert np.abs(ny) == pytest.approx([1.0, 1.0])
