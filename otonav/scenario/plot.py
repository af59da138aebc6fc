"""The trajectory picture: path, obstacles and walls, goal and tolerance, closest approach."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

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


def draw_trajectory(
    trajectory: list[tuple[float, float, float]],
    obstacles: tuple[Obstacle, ...] | None,
    goal: tuple[float, float] | None,
    tolerance: float | None,
    closest: tuple[float, float] | None,
    title: str,
    *,
    path_label: str = "path (ground truth)",
) -> Figure:
    """The figure of a run: ``trajectory`` as (t, x, y), the obstacles (``None``:
    not known, and the figure says so), the goal and its tolerance circle (``None``:
    not known, said likewise), the closest approach."""
    # Imported here: matplotlib costs ~0.3 s, and only a drawn plot needs it. A Figure
    # on an Agg canvas, not pyplot: no global figure registry (runs plot from worker
    # threads at once) and no backend forced on a host process.
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle, PathPatch

    fig = Figure(figsize=(6.4, 4.8), dpi=100)
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
    span_x = [*xs, *(goal[:1] if goal else ())] or [0.0]
    span_y = [*ys, *(goal[1:] if goal else ())] or [0.0]
    ax.set_xlim(min(span_x) - 1.0, max(span_x) + 1.0)
    ax.set_ylim(min(span_y) - 1.0, max(span_y) + 1.0)
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
    ax.legend(loc="best", fontsize=8)
    return fig


def plot_trajectory(
    path: Path,
    trajectory: list[tuple[float, float, float]],
    obstacles: tuple[Obstacle, ...] | None,
    goal: tuple[float, float] | None,
    tolerance: float | None,
    closest: tuple[float, float] | None,
    title: str,
    *,
    path_label: str = "path (ground truth)",
) -> Path:
    """Write a PNG of the run (:func:`draw_trajectory`) to ``path`` and return it."""
    fig = draw_trajectory(
        trajectory, obstacles, goal, tolerance, closest, title, path_label=path_label
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, metadata={"Software": None})
    return path
