"""The trajectory picture: path, obstacles and walls, goal and tolerance, closest approach."""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

from otonav.hal import BoxObstacle

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def _corners(box: BoxObstacle) -> list[tuple[float, float]]:
    c, s = math.cos(box.yaw), math.sin(box.yaw)
    return [
        (box.x + c * dx - s * dy, box.y + s * dx + c * dy)
        for dx, dy in (
            (-box.half_x, -box.half_y),
            (box.half_x, -box.half_y),
            (box.half_x, box.half_y),
            (-box.half_x, box.half_y),
        )
    ]


def draw_trajectory(
    trajectory: list[tuple[float, float, float]],
    obstacles: tuple[BoxObstacle, ...] | None,
    goal: tuple[float, float] | None,
    tolerance: float | None,
    closest: tuple[float, float] | None,
    title: str,
    *,
    path_label: str = "path (ground truth)",
) -> Figure:
    """The figure of a run: ``trajectory`` as (t, x, y), the obstacle boxes (``None``:
    not known, and the figure says so), the goal and its tolerance circle (``None``:
    not known, said likewise), the closest approach."""
    # Imported here: matplotlib costs ~0.3 s, and only a drawn plot needs it. A Figure
    # on an Agg canvas, not pyplot: no global figure registry (runs plot from worker
    # threads at once) and no backend forced on a host process.
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle, Polygon

    fig = Figure(figsize=(6.4, 4.8), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    unknown = []
    for i, box in enumerate(obstacles or ()):
        ax.add_patch(
            Polygon(
                _corners(box),
                closed=True,
                color="#d98c33",
                alpha=0.9,
                label="obstacles, walls" if i == 0 else None,
            )
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
    obstacles: tuple[BoxObstacle, ...] | None,
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
