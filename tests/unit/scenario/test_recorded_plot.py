"""``otonav plot`` and the pytest plugin's kept ``trajectory.png`` draw a recording as it
is: the goal from /goal, the obstacles the recording says are there, "unknown" where
it says nothing, odometry called odometry, and a cut-off file drawn from its complete
chunks. The figure is checked through its artists, not its pixels."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
from matplotlib.patches import Polygon
from matplotlib.path import Path as Path_

from otonav.cli import main
from otonav.hal import BoxObstacle
from otonav.msgs import Header, Odometry, Point, Pose, PoseStamped, PoseWithCovariance, Time
from otonav.record._writer import RecordingWriter
from otonav.scenario._plot import box_outlines, draw_trajectory, key_poses
from otonav.scenario._replay import plot_recording, recorded_plot
from otonav.stack._worldmeta import WORLD_METADATA

pytestmark = pytest.mark.unit

GOAL = (2.5, -1.25)
BOXES = "[[1.0, 0.5, 0.2, 0.3, 0.0], [2.0, -0.5, 0.25, 0.25, 0.4]]"
WALLS = "[[0.0, 5.1, 5.2, 0.1, 0.0]]"


def _odom(x: float, y: float, t: float) -> Odometry:
    return Odometry(
        header=Header(stamp=Time.from_seconds(t), frame_id="odom"),
        pose=PoseWithCovariance(pose=Pose(position=Point(x=x, y=y))),
    )


def _recording(path: Path, *, goal: bool = True, world: bool = False, seconds: float = 2.0) -> Path:
    """A recording like the pytest plugin's: /goal, then /odom at 100 Hz; no scenario."""
    with RecordingWriter(path, chunk_size=4096) as writer:
        if world:
            writer.add_metadata(WORLD_METADATA, {"obstacles": BOXES, "walls": WALLS})
        if goal:
            writer.write("/goal", PoseStamped(pose=Pose(position=Point(x=GOAL[0], y=GOAL[1]))), 0.0)
        for i in range(round(seconds * 100)):
            t = i / 100
            writer.write("/odom", _odom(t, -t / 2, t), t)
    return path


def _legend(fig: object) -> list[str]:
    (legend,) = fig.legends  # type: ignore[attr-defined]
    return [t.get_text() for t in legend.get_texts()]


def _notes(fig: object) -> str:
    (ax,) = fig.axes  # type: ignore[attr-defined]
    return " ".join(t.get_text() for t in ax.texts)


def _figure(recording: Path) -> object:
    p = recorded_plot(recording)
    return draw_trajectory(
        p.trajectory, p.obstacles, p.goal, p.tolerance, None, p.title, path_label="path (odometry)"
    )


def test_the_goal_comes_from_the_goal_topic(tmp_path: Path) -> None:
    plot = recorded_plot(_recording(tmp_path / "r.mcap"))
    assert plot.goal == GOAL
    assert len(plot.trajectory) == 200


def test_no_goal_and_no_world_are_said_not_drawn_at_the_origin(tmp_path: Path) -> None:
    recording = _recording(tmp_path / "r.mcap", goal=False)
    plot = recorded_plot(recording)
    assert plot.goal is None
    assert plot.obstacles is None
    fig = _figure(recording)
    assert "goal" not in _legend(fig)
    assert "goal unknown" in _notes(fig)
    assert "obstacles unknown" in _notes(fig)


def test_the_legend_says_odometry_like_the_title(tmp_path: Path) -> None:
    recording = _recording(tmp_path / "r.mcap")
    fig = _figure(recording)
    assert "path (odometry)" in _legend(fig)
    assert not any("ground truth" in label for label in _legend(fig))
    assert "(odometry)" in recorded_plot(recording).title


def test_obstacles_and_walls_are_drawn_where_the_recording_says(tmp_path: Path) -> None:
    recording = _recording(tmp_path / "r.mcap", world=True)
    plot = recorded_plot(recording)
    assert plot.obstacles == (
        BoxObstacle(1.0, 0.5, 0.2, 0.3, 0.0),
        BoxObstacle(2.0, -0.5, 0.25, 0.25, 0.4),
        BoxObstacle(0.0, 5.1, 5.2, 0.1, 0.0),
    )
    fig = _figure(recording)
    (ax,) = fig.axes  # type: ignore[attr-defined]
    (boxes,) = [p for p in ax.patches if p.get_label() == "obstacles, walls"]
    codes = boxes.get_path().codes
    assert type(boxes).__name__ == "PathPatch"  # one artist for all boxes (issue 30)
    assert codes is not None
    assert list(codes).count(Path_.CLOSEPOLY) == 3
    assert "unknown" not in _notes(fig)


def test_plot_of_a_cut_off_recording_draws_the_complete_chunks_with_a_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    whole = _recording(tmp_path / "whole.mcap", world=True, seconds=10.0)
    cut = tmp_path / "cut.mcap"
    data = whole.read_bytes()
    cut.write_bytes(data[: len(data) * 2 // 3])  # a SIGKILL mid-run: no footer, no index
    png = tmp_path / "cut.png"
    assert main(["plot", str(cut), "--out", str(png)]) == 0
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert err.startswith(f"otonav: warning: {cut} was cut off"), err
    assert png.stat().st_size > 10_000
    plot = recorded_plot(cut)
    assert plot.truncated
    assert "cut off" in plot.title
    assert plot.goal == GOAL
    assert plot.obstacles is not None
    assert len(plot.obstacles) == 3
    assert 0 < len(plot.trajectory) < 1000
    assert [t for t, _x, _y in plot.trajectory] == sorted(t for t, _x, _y in plot.trajectory)


def test_plot_recording_writes_a_png(tmp_path: Path) -> None:
    png = plot_recording(_recording(tmp_path / "r.mcap"), tmp_path / "out.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_box_outlines_are_the_boxes_corners() -> None:
    """The vectorised outlines put each corner where the box's own geometry says."""
    boxes = (BoxObstacle(1.0, 0.5, 0.2, 0.3, 0.7), BoxObstacle(-2.0, 3.0, 1.5, 0.05, -2.0))
    outlines = box_outlines(boxes)
    assert outlines.shape == (2, 5, 2)
    for box, outline in zip(boxes, outlines, strict=True):
        for x, y in outline[:4]:
            assert box.distance_to(x, y) == pytest.approx(0.0, abs=1e-12)  # on the box
            c, s = math.cos(box.yaw), math.sin(box.yaw)
            lx = c * (x - box.x) + s * (y - box.y)
            ly = -s * (x - box.x) + c * (y - box.y)
            assert (abs(lx), abs(ly)) == pytest.approx((box.half_x, box.half_y))  # a corner
        assert list(outline[4]) == list(outline[0])


def test_the_legend_and_the_title_cover_nothing_and_are_not_clipped(tmp_path: Path) -> None:
    """Issue 39: the legend placed "best" on the map hid the goal. It sits beside the map
    now: its box does not overlap the axes', and the title is inside the figure."""
    fig: Any = _figure(_recording(tmp_path / "r.mcap", world=True))
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    (ax,) = fig.axes
    (legend,) = fig.legends
    map_box, legend_box = ax.get_window_extent(renderer), legend.get_window_extent(renderer)
    assert not map_box.overlaps(legend_box)
    title = ax.title.get_window_extent(renderer)
    assert fig.bbox.contains(title.x0, title.y0)
    assert fig.bbox.contains(title.x1, title.y1)
    assert fig.bbox.contains(legend_box.x1, legend_box.y0)


def test_a_box_the_window_cuts_is_drawn_whole_and_a_wall_stays_cut() -> None:
    """Issue 39 item 12: the acceptance plot cut the box at y = -1 in half. The window is
    the path and the goal +- 1 m: here x in [-1, 3], y in [-1, 1.5]."""
    box = BoxObstacle(1.0, -1.0, 0.2, 0.1, 0.5)  # across the window's lower edge
    wall = BoxObstacle(0.0, 1.5, 20.0, 0.1, 0.0)  # across its upper edge, 40 m long
    trajectory = [(0.0, 0.0, 0.0), (1.0, 1.0, 0.5)]
    fig: Any = draw_trajectory(trajectory, (box, wall), (2.0, 0.5), 0.15, None, "t")
    (ax,) = fig.axes
    (bottom, top), (left, right) = ax.get_ylim(), ax.get_xlim()
    assert bottom == pytest.approx(box_outlines((box,))[0][:, 1].min())  # the whole box
    assert top == pytest.approx(1.6)  # the wall's whole thickness
    assert (left, right) == pytest.approx((-2.0, 4.0))  # its length: at most 1 m more


def test_the_footprint_is_drawn_at_start_closest_approach_and_end() -> None:
    """Issue 38: the robot's outline, turned the way it drove, at the three poses."""
    trajectory = [(0.1 * i, 0.1 * i, 0.0) for i in range(11)]  # along +x to (1, 0)
    trajectory += [(1.1 + 0.1 * i, 1.0, 0.1 * (i + 1)) for i in range(10)]  # then +y
    poses = key_poses(trajectory, math.pi, (1.0, 0.5))
    assert poses[0] == (0.0, 0.0, math.pi)  # the start as given
    assert poses[1][:2] == (1.0, 0.5)
    assert poses[1][2] == pytest.approx(math.pi / 2)  # driving +y there
    assert poses[2][:2] == (1.0, 1.0)
    assert poses[2][2] == pytest.approx(math.pi / 2)
    footprint = ((-0.1, -0.2), (0.3, -0.2), (0.3, 0.2), (-0.1, 0.2))
    fig = draw_trajectory(trajectory, (), None, None, None, "t", footprint=footprint, poses=poses)
    drawn = [p for p in fig.axes[0].patches if isinstance(p, Polygon)]
    assert len(drawn) == 3
    corners = drawn[2].get_xy()[:4]  # at the end, facing +y: x' = x - y_b, y' = y + x_b
    expected = [1.2, 0.9, 1.2, 1.3, 0.8, 1.3, 0.8, 0.9]
    assert corners.ravel().tolist() == pytest.approx(expected)
