"""The trajectory picture: path, obstacles and walls, goal and tolerance, closest approach."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from otonav.hal import BoxObstacle, PolygonObstacle, RoundObstacle

if TYPE_CHECKING:
    from matplotlib.figure import Figure
    from matplotlib.path import Path as MplPath

_CORNERS = np.array([(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0)])
"""A box's outline in half sizes, counter-clockwise, closed (the 5th vertex is unused)."""


def box_outlines(boxes: tuple[BoxObstacle, ...]) -> NDArray[np.float64]:
    """Every box's outline, shape (n, 5, 2): four corners counter-clockwise, then the
    first again (where a path closes), m in the world frame."""
    b = np.array([(o.x, o.y, o.half_x, o.half_y, o.yaw) for o in boxes]).reshape(-1, 5)
    local = _CORNERS[None, :, :] * b[:, None, 2:4]
    c, s = np.cos(b[:, 4])[:, None], np.sin(b[:, 4])[:, None]
    x = b[:, 0:1] + c * local[:, :, 0] - s * local[:, :, 1]
    y = b[:, 1:2] + s * local[:, :, 0] + c * local[:, :, 1]
    return np.stack((x, y), axis=-1)


Obstacle = BoxObstacle | RoundObstacle | PolygonObstacle


def _boxes_path(obstacles: tuple[Obstacle, ...]) -> MplPath:
    """All boxes and disks as one compound path: one artist to draw, and one vertex
    array for the legend's "best" placement to test (a patch per box made it test each
    one: 3000 boxes drew in 1.7 s, issue 30). The outlines all turn the same way, so
    where they overlap the non-zero fill rule fills them once."""
    from matplotlib.path import Path as MplPath

    boxes = tuple(o for o in obstacles if isinstance(o, BoxObstacle))
    outlines = box_outlines(boxes)
    codes = np.tile(
        np.array([MplPath.MOVETO, *[MplPath.LINETO] * 3, MplPath.CLOSEPOLY], MplPath.code_type),
        len(boxes),
    )
    paths = [MplPath(outlines.reshape(-1, 2), codes)]
    unit = MplPath.circle()  # Bezier arcs, counter-clockwise like the box outlines
    circle: NDArray[np.float64] = np.asarray(unit.vertices, dtype=np.float64)
    paths += [
        MplPath(circle * o.radius + np.array((o.x, o.y)), unit.codes)
        for o in obstacles
        if isinstance(o, RoundObstacle)
    ]
    paths += [
        MplPath(np.array([*o.points, o.points[0]]), closed=True)
        for o in obstacles
        if isinstance(o, PolygonObstacle)
    ]
    return MplPath.make_compound_path(*paths)


def key_poses(
    trajectory: Sequence[tuple[float, float, float]],
    start_yaw: float,
    closest: tuple[float, float] | None,
) -> list[tuple[float, float, float]]:
    """(x, y, yaw) at the start, at the sample nearest ``closest`` and at the end of a
    (t, x, y) trajectory; the heading along the path there (a diff-drive robot drives
    where it faces), the start's as given."""
    if not trajectory:
        return []

    def heading(i: int) -> float:
        x, y = trajectory[i][1:]
        for j in (*range(i - 1, -1, -1), *range(i + 1, len(trajectory))):
            px, py = trajectory[j][1:]
            if math.hypot(x - px, y - py) > 0.02:  # a step that says where it went
                return math.atan2(y - py, x - px) if j < i else math.atan2(py - y, px - x)
        return start_yaw

    poses = [(trajectory[0][1], trajectory[0][2], start_yaw)]
    if closest is not None and not math.isnan(closest[0]):
        near = min(
            range(len(trajectory)),
            key=lambda i: math.hypot(trajectory[i][1] - closest[0], trajectory[i][2] - closest[1]),
        )
        poses.append((trajectory[near][1], trajectory[near][2], heading(near)))
    last = len(trajectory) - 1
    poses.append((trajectory[last][1], trajectory[last][2], heading(last)))
    return poses


def draw_trajectory(
    trajectory: list[tuple[float, float, float]],
    obstacles: tuple[Obstacle, ...] | None,
    goal: tuple[float, float] | None,
    tolerance: float | None,
    closest: tuple[float, float] | None,
    title: str,
    *,
    path_label: str = "path (ground truth)",
    footprint: Sequence[tuple[float, float]] = (),
    poses: Sequence[tuple[float, float, float]] = (),
) -> Figure:
    """The figure of a run: ``trajectory`` as (t, x, y), the obstacles (``None``:
    not known, and the figure says so), the goal and its tolerance circle (``None``:
    not known, said likewise), the closest approach; the robot's ``footprint`` (base
    frame) drawn at each of ``poses`` (x, y, yaw), e.g. start, closest approach, end."""
    # Imported here: matplotlib costs ~0.3 s, and only a drawn plot needs it. A Figure
    # on an Agg canvas, not pyplot: no global figure registry (runs plot from worker
    # threads at once) and no backend forced on a host process.
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle, PathPatch, Polygon

    # Constrained layout: the title and the legend beside the map are never clipped.
    fig = Figure(figsize=(8.0, 4.8), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    unknown = []
    if obstacles:
        # add_artist, not add_patch: the limits are set below from the path and the goal,
        # and add_patch walked every segment in Python to grow them (0.14 s at 1000 boxes).
        ax.add_artist(
            PathPatch(_boxes_path(obstacles), color="#d98c33", alpha=0.9, label="obstacles, walls")
        )
    if obstacles is None:
        unknown.append("obstacles unknown")
    xs = [p[1] for p in trajectory]
    ys = [p[2] for p in trajectory]
    if xs:
        ax.plot(xs, ys, color="#1f5fbf", linewidth=2, label=path_label)
        ax.plot(xs[0], ys[0], "o", color="#1f5fbf", label="start")
    if goal is not None:
        if tolerance is not None:
            ax.add_patch(Circle(goal, tolerance, fill=False, color="#2a9d2a", linewidth=2))
        ax.plot(*goal, "*", color="#2a9d2a", markersize=12, label="goal")
    else:
        unknown.append("goal unknown")
    if closest is not None and not math.isnan(closest[0]):
        ax.plot(*closest, "x", color="#c0392b", markersize=10, label="closest approach")
    for i, (x, y, yaw) in enumerate(poses if footprint else ()):
        c, s = math.cos(yaw), math.sin(yaw)
        outline = [(x + c * px - s * py, y + s * px + c * py) for px, py in footprint]
        ax.add_patch(
            Polygon(outline, fill=False, color="#555555", linewidth=1, label=None if i else "robot")
        )
    span_x = [*xs, *(goal[:1] if goal else ())] or [0.0]
    span_y = [*ys, *(goal[1:] if goal else ())] or [0.0]
    x0, x1, y0, y1 = min(span_x) - 1.0, max(span_x) + 1.0, min(span_y) - 1.0, max(span_y) + 1.0
    boxes = tuple(o for o in obstacles or () if isinstance(o, BoxObstacle))
    if boxes:  # a box the window cuts is drawn whole, up to 1 m more (walls stay cut)
        corners = box_outlines(boxes)
        lo, hi = corners.min(axis=1), corners.max(axis=1)
        cut = (lo[:, 0] < x1) & (hi[:, 0] > x0) & (lo[:, 1] < y1) & (hi[:, 1] > y0)
        if cut.any():
            x0, y0 = np.maximum(np.minimum((x0, y0), lo[cut].min(axis=0)), (x0 - 1.0, y0 - 1.0))
            x1, y1 = np.minimum(np.maximum((x1, y1), hi[cut].max(axis=0)), (x1 + 1.0, y1 + 1.0))
    ax.set_xlim(float(x0), float(x1))
    ax.set_ylim(float(y0), float(y1))
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    if unknown:  # said on the picture: an absent mark must not read as "nothing there"
        ax.text(
            0.02,
            0.02,
            "; ".join(unknown) + " (not in the recording)",
            transform=ax.transAxes,
            fontsize=8,
            color="#c0392b",
        )
    if ax.get_legend_handles_labels()[1]:  # nothing drawn (every chunk damaged): no legend
        # Beside the map, not on it: "best" still hid the goal or the path (issue 39).
        fig.legend(loc="outside right upper", fontsize=8)
    return fig


def plot_trajectory(path: Path, *args: Any, **kwargs: Any) -> Path:
    """Write a PNG of the run (:func:`draw_trajectory` of the other arguments) to ``path``."""
    fig = draw_trajectory(*args, **kwargs)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, metadata={"Software": None})
    return path
