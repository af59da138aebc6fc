"""The trajectory picture: path, obstacles and walls, goal and tolerance, closest approach."""

from __future__ import annotations

import math
from pathlib import Path

from otonav.hal import BoxObstacle


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


def plot_trajectory(
    path: Path,
    trajectory: list[tuple[float, float, float]],
    obstacles: tuple[BoxObstacle, ...],
    goal: tuple[float, float],
    tolerance: float,
    closest: tuple[float, float] | None,
    title: str,
) -> Path:
    """Write a PNG of the run to ``path`` and return it."""
    # Imported here: matplotlib costs ~0.3 s, and only a drawn plot needs it. A Figure
    # on an Agg canvas, not pyplot: no global figure registry (runs plot from worker
    # threads at once) and no backend forced on a host process.
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle, Polygon

    fig = Figure(figsize=(6.4, 4.8), dpi=100)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    for box in obstacles:
        ax.add_patch(Polygon(_corners(box), closed=True, color="#d98c33", alpha=0.9))
    xs = [p[1] for p in trajectory]
    ys = [p[2] for p in trajectory]
    if xs:
        ax.plot(xs, ys, color="#1f5fbf", linewidth=2, label="path (ground truth)")
        ax.plot(xs[0], ys[0], "o", color="#1f5fbf", label="start")
    ax.add_patch(Circle(goal, tolerance, fill=False, color="#2a9d2a", linewidth=2))
    ax.plot(*goal, "*", color="#2a9d2a", markersize=12, label="goal")
    if closest is not None and not math.isnan(closest[0]):
        ax.plot(*closest, "x", color="#c0392b", markersize=10, label="closest approach")
    span_x = [*xs, goal[0]]
    span_y = [*ys, goal[1]]
    ax.set_xlim(min(span_x) - 1.0, max(span_x) + 1.0)
    ax.set_ylim(min(span_y) - 1.0, max(span_y) + 1.0)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, metadata={"Software": None})
    return path
