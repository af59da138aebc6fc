"""The report's pictures. matplotlib is imported here only, when a report is drawn (a
sweep that only runs never pays its ~0.3 s import), and through a Figure on an Agg
canvas: no pyplot global state, no backend forced on a host process."""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path
from typing import Any


def _figure(w: float, h: float) -> Any:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(w, h), dpi=100)
    FigureCanvasAgg(fig)
    return fig


def _combo(record: dict[str, Any]) -> str:
    o = record.get("overrides") or {}
    return ", ".join(f"{k}={v}" for k, v in o.items()) or "(no overrides)"


def _world(record: dict[str, Any]) -> str:
    return str(record["scenario"])


def pass_fail_grid(records: Sequence[dict[str, Any]], png: Path) -> Path:
    """One cell per world (columns) and override combination (rows): the share of its
    runs (over seeds) that passed, red 0 .. green 1; a cross marks an error."""
    worlds = list(dict.fromkeys(_world(r) for r in records))
    combos = list(dict.fromkeys(_combo(r) for r in records))
    cells: dict[tuple[int, int], list[dict[str, Any]]] = defaultdict(list)
    for r in records:
        cells[(combos.index(_combo(r)), worlds.index(_world(r)))].append(r)
    grid = [[float("nan")] * len(worlds) for _ in combos]
    for (row, col), runs in cells.items():
        grid[row][col] = sum(r["status"] == "passed" for r in runs) / len(runs)
    width = min(16.0, max(5.0, 0.25 * len(worlds) + 3.0))
    height = min(12.0, max(2.5, 0.35 * len(combos) + 1.8))
    fig = _figure(width, height)
    ax = fig.add_subplot(1, 1, 1)
    image = ax.imshow(grid, cmap="RdYlGn", vmin=0.0, vmax=1.0, aspect="auto")
    for (row, col), runs in cells.items():
        if any(r["status"] == "error" for r in runs):
            ax.plot(col, row, marker="x", color="black", markersize=6)
    ax.set_yticks(range(len(combos)), combos, fontsize=7)
    if len(worlds) <= 40:
        ax.set_xticks(range(len(worlds)), worlds, rotation=90, fontsize=7)
    else:
        ax.set_xlabel(f"{len(worlds)} worlds, in sweep order")
    fig.colorbar(image, ax=ax, label="share of runs passed")
    ax.set_title("pass / fail per world (x: error)")
    fig.tight_layout()
    fig.savefig(png)
    return png


def histograms(records: Sequence[dict[str, Any]], png: Path) -> Path:
    """Time to goal (runs that reached it) and minimum clearance (every judged run)."""
    ttg = [r["time_to_goal_s"] for r in records if r.get("time_to_goal_s") is not None]
    clearance = [r["min_clearance_m"] for r in records if r.get("min_clearance_m") is not None]
    fig = _figure(9.0, 3.6)
    for i, (values, label) in enumerate(
        ((ttg, "time to goal (s of sim time)"), (clearance, "minimum clearance (m)"))
    ):
        ax = fig.add_subplot(1, 2, i + 1)
        if values:
            ax.hist(values, bins=min(30, max(5, len(values) // 5)), color="tab:blue")
        else:
            ax.text(0.5, 0.5, "no data", ha="center", va="center", transform=ax.transAxes)
        ax.set_xlabel(label)
        ax.set_ylabel("runs")
    fig.tight_layout()
    fig.savefig(png)
    return png
