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


def _combo(record: dict[str, Any], shown: frozenset[str] | None = None) -> str:
    """The run's override combination, as labels say it: only the ``shown`` keys (those
    that vary across the sweep; a key every run sets alike says nothing)."""
    o = record.get("overrides") or {}
    return ", ".join(f"{k}={v}" for k, v in o.items() if shown is None or k in shown) or (
        "(no overrides)"
    )


def varying_keys(records: Sequence[dict[str, Any]]) -> frozenset[str]:
    """The override keys whose value differs between runs."""
    values: dict[str, set[str]] = defaultdict(set)
    for r in records:
        for k, v in (r.get("overrides") or {}).items():
            values[k].add(repr(v))
    keys = {k for r in records for k in (r.get("overrides") or {})}
    return frozenset(
        k
        for k in keys
        if len(values[k]) > 1 or any(k not in (r.get("overrides") or {}) for r in records)
    )


def _world(record: dict[str, Any]) -> str:
    return str(record["scenario"])


STRIP_RUNS = 60
"""Up to this many runs a panel shows every run as a dot; beyond, step histograms."""


def _message(fig: Any, text: str) -> None:
    """A figure that says in words what there is to see (when there is nothing to plot)."""
    ax = fig.add_subplot(1, 1, 1)
    ax.axis("off")
    ax.text(0.5, 0.5, text, ha="center", va="center", wrap=True, fontsize=11)


def pass_fail_grid(records: Sequence[dict[str, Any]], png: Path) -> Path:
    """One cell per world (columns) and override combination (rows): the share of its
    runs (over seeds) that passed, red 0 .. green 1; a cross marks an error. When every
    run passed, the picture says so in words (a green band teaches nothing)."""
    shown = varying_keys(records)
    worlds = list(dict.fromkeys(_world(r) for r in records))
    combos = list(dict.fromkeys(_combo(r, shown) for r in records))
    if all(r["status"] == "passed" for r in records):
        fig = _figure(6.0, 2.0)
        _message(
            fig,
            f"all {len(records)} runs passed: {len(worlds)} world(s) x {len(combos)} "
            "override combination(s), no cell to tell apart",
        )
        fig.savefig(png)
        return png
    cells: dict[tuple[int, int], list[dict[str, Any]]] = defaultdict(list)
    for r in records:
        cells[(combos.index(_combo(r, shown)), worlds.index(_world(r)))].append(r)
    grid = [[float("nan")] * len(worlds) for _ in combos]
    for (row, col), runs in cells.items():
        grid[row][col] = sum(r["status"] == "passed" for r in runs) / len(runs)
    width = min(16.0, max(7.0, 0.25 * len(worlds) + 3.0))
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
    failed = sum(r["status"] != "passed" for r in records)
    ax.set_title(f"{failed} of {len(records)} runs failed\n(share passed per world; x: error)")
    fig.tight_layout()
    fig.savefig(png)
    return png


def histograms(records: Sequence[dict[str, Any]], png: Path) -> Path:
    """Time to goal (runs that reached it) and minimum clearance (every judged run), one
    outline per override combination (a mix of them would be a many-humped shape), with
    the limits drawn: the longest budget and the clearance floor."""
    groups: dict[str, list[dict[str, Any]]] = defaultdict(list)
    shown_keys = varying_keys(records)
    for r in records:
        groups[_combo(r, shown_keys)].append(r)
    budgets = [r["sim_budget_s"] for r in records if r.get("sim_budget_s")]
    floors = [r["clearance_floor_m"] for r in records if r.get("clearance_floor_m")]
    panels = (
        ("time_to_goal_s", "time to goal (s of sim time)", max(budgets, default=None), "budget",
         "no run reached the goal: no times to show", "never reached the goal"),
        ("min_clearance_m", "minimum clearance (m)", max(floors, default=None), "floor",
         "no run was judged: no clearances to show", "not judged (errors)"),
    )  # fmt: skip
    from matplotlib.ticker import MaxNLocator

    fig = _figure(10.0, 3.8)
    for i, (key, label, limit, limit_name, empty, unshown) in enumerate(panels):
        ax = fig.add_subplot(1, 2, i + 1)
        values = {c: [r[key] for r in rs if r.get(key) is not None] for c, rs in groups.items()}
        shown = {c: v for c, v in values.items() if v}
        if not shown:
            ax.axis("off")
            ax.text(0.5, 0.5, empty, ha="center", va="center", transform=ax.transAxes)
            continue
        every = [v for vs in shown.values() for v in vs]
        if len(every) <= STRIP_RUNS:  # few runs: each one a dot, a row per combination
            for row, (combo, vs) in enumerate(shown.items()):
                ax.plot(vs, [row] * len(vs), "o", alpha=0.7, label=f"{combo} ({len(vs)})")
            ax.set_yticks(range(len(shown)), list(shown), fontsize=7)
            ax.set_ylim(-0.5, len(shown) - 0.5)
        else:
            lo = min(every + ([limit] if limit else []))
            hi = max(every + ([limit] if limit else []))
            bins = [lo + (hi - lo) * k / 20 for k in range(21)] if hi > lo else 10
            for combo, vs in shown.items():
                ax.hist(vs, bins=bins, histtype="step", linewidth=1.5, label=f"{combo} ({len(vs)})")
            ax.set_ylabel("runs")
            ax.yaxis.set_major_locator(MaxNLocator(integer=True))
            ax.legend(fontsize=7)
        if limit:
            ax.axvline(limit, color="red", linestyle="--")
            ax.annotate(
                f"{limit_name} {limit:g}", (limit, 1.0), xycoords=("data", "axes fraction"),
                ha="right", va="bottom", color="red", fontsize=8,
            )  # fmt: skip
        ax.set_xlabel(label)
        missing = sum(len(rs) for rs in groups.values()) - len(every)
        if missing:
            ax.set_title(f"not shown: {missing} run(s) {unshown}", fontsize=8, loc="left")
    if sum(len(rs) for rs in groups.values()) <= STRIP_RUNS:
        fig.suptitle("each dot a run, a row per override combination; red: the limit", fontsize=9)
    fig.tight_layout()
    fig.savefig(png)
    return png
