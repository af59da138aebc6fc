"""``summary.json`` and ``report.md`` (with its plots) from the result records."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from otonav.sweep._stats import (
    Rate,
    failures_by_reason,
    group_rates,
    override_rates,
    pass_rate,
    spread,
)

SUMMARY = "summary.json"
REPORT = "report.md"
GRID_PNG = "pass_fail.png"
HIST_PNG = "histograms.png"
#: Failures listed one by one per reason group in report.md (summary.json has them all).
LISTED_PER_GROUP = 10
_FAILURE_KEYS = (
    "run_id", "scenario", "seed", "overrides", "status", "reason", "repro", "artifacts"
)  # fmt: skip


def summarize(records: Sequence[dict[str, Any]], *, planned: int, name: str) -> dict[str, Any]:
    """Everything the report says, as JSON data."""
    judged = [r for r in records if r.get("status") != "error"]
    failures = failures_by_reason(records)
    sim = sum(r.get("sim_time_s") or 0.0 for r in records)
    return {
        "name": name,
        "planned": planned,
        "finished": len(records),
        "complete": len(records) == planned,
        "pass_rate": pass_rate(records).as_dict(),
        "by_family": {k: v.as_dict() for k, v in group_rates(records, _family).items()},
        "by_override": {
            key: {value: rate.as_dict() for value, rate in rates.items()}
            for key, rates in override_rates(records).items()
        },
        "time_to_goal_s": spread(r.get("time_to_goal_s") for r in judged),
        "min_clearance_m": spread(r.get("min_clearance_m") for r in judged),
        "sim_time_s": sim,
        "run_wall_time_s": spread(r.get("wall_time_s") for r in records),
        "failures": [
            {
                "reason": reason,
                "count": len(runs),
                "runs": [{k: r.get(k) for k in _FAILURE_KEYS} for r in runs],
            }
            for reason, runs in failures.items()
        ],
    }


def _family(record: dict[str, Any]) -> str:
    return str(record.get("family", record.get("scenario")))


def _pct(rate: dict[str, Any]) -> str:
    if rate["rate"] is None:
        return "-"
    errors = f", {rate['errors']} errors" if rate["errors"] else ""
    return (
        f"{100 * rate['rate']:.1f} % [{100 * rate['low']:.1f}, {100 * rate['high']:.1f}] "
        f"({rate['passed']}/{rate['runs']}{errors})"
    )


def _num(value: float | None, unit: str) -> str:
    return "-" if value is None else f"{value:.3f} {unit}"


def _margin(record: dict[str, Any]) -> float:
    """How far the run stayed above its clearance floor (m; -inf when not judged)."""
    clearance, floor = record.get("min_clearance_m"), record.get("clearance_floor_m") or 0.0
    return float("-inf") if clearance is None else float(clearance) - float(floor)


def worst_case(records: Sequence[dict[str, Any]]) -> list[str]:
    """The report's first lines: the worst run, its figures against the limits, and its
    one-line repro. A failed run is worse than any pass; among equals, the one closest
    to (or furthest below) the clearance floor."""
    if not records:
        return []
    worst = min(records, key=lambda r: (r.get("status") == "passed", _margin(r)))
    sets = ", ".join(f"{k}={v}" for k, v in (worst.get("overrides") or {}).items())
    clearance = worst.get("min_clearance_m")
    floor = worst.get("clearance_floor_m")
    ttg, budget = worst.get("time_to_goal_s"), worst.get("sim_budget_s")
    lines = [
        "## Worst case",
        "",
        f"- run `{worst['run_id']}`: `{worst['scenario']}` seed {worst['seed']}"
        + (f", {sets}" if sets else "")
        + f": **{worst['status']}**, {worst.get('reason', '')}",
        f"- min clearance {_num(clearance, 'm')}"
        + (f" (floor {floor:g} m)" if floor else "")
        + f"; time to goal {_num(ttg, 's')}"
        + (f" (budget {budget:g} s)" if budget else ""),
    ]
    if worst.get("repro"):
        lines.append(f"- repro: `{worst['repro']}`")
    return [*lines, ""]


def write_report(out: Path, summary: dict[str, Any], records: Sequence[dict[str, Any]]) -> Path:
    """Write ``summary.json``, the plots and ``report.md`` into ``out``."""
    from otonav.sweep._plots import histograms, pass_fail_grid

    (out / SUMMARY).write_text(json.dumps(summary, indent=2, sort_keys=True) + "\n")
    pictures = []
    if records:
        pictures = [pass_fail_grid(records, out / GRID_PNG), histograms(records, out / HIST_PNG)]
    lines = [f"# Sweep report: {summary['name']}", "", *worst_case(records)]
    if not summary["complete"]:
        lines += [
            f"**Incomplete:** {summary['finished']} of {summary['planned']} runs finished "
            "(finish with `--resume`).",
            "",
        ]
    lines += [
        "Pass rates with their Wilson 95 % interval; errors (a crashed or hung run) count "
        "as not passed.",
        "",
        "| group | pass rate [95 % CI] |",
        "|---|---|",
        f"| **all runs** | {_pct(summary['pass_rate'])} |",
    ]
    lines += [f"| family `{k}` | {_pct(v)} |" for k, v in summary["by_family"].items()]
    for key, values in summary["by_override"].items():
        lines += [f"| `{key}` = {value} | {_pct(rate)} |" for value, rate in values.items()]
    lines += ["", "| figure | p50 | p95 | max | runs |", "|---|---|---|---|---|"]
    for key, unit, label in (
        ("time_to_goal_s", "s", "time to goal"),
        ("min_clearance_m", "m", "min clearance"),
    ):
        s = summary[key]
        lines.append(
            f"| {label} | {_num(s['p50'], unit)} | {_num(s['p95'], unit)} | "
            f"{_num(s['max'], unit)} | {s['count']} |"
        )
    lines += [""] + [f"![{p.stem}]({p.name})" for p in pictures] + [""]
    lines += ["## Failures by reason", ""]
    if not summary["failures"]:
        lines += ["None.", ""]
    for group in summary["failures"]:
        lines += [f"### {group['reason']} ({group['count']})", ""]
        for run in group["runs"][:LISTED_PER_GROUP]:
            sets = ", ".join(f"{k}={v}" for k, v in (run["overrides"] or {}).items())
            sets = f", {sets}" if sets else ""
            lines.append(f"- `{run['scenario']}` seed {run['seed']}{sets}")
            if run["status"] == "error":
                lines.append(f"  - error: {run['reason']}")
            if run["repro"]:
                lines.append(f"  - repro: `{run['repro']}`")
            if run["artifacts"]:
                folder = run["artifacts"]
                lines.append(
                    f"  - [recording]({folder}/recording.mcap), [plot]({folder}/trajectory.png)"
                )
        hidden = group["count"] - LISTED_PER_GROUP
        if hidden > 0:
            lines.append(f"- … and {hidden} more (all in summary.json)")
        lines.append("")
    report = out / REPORT
    report.write_text("\n".join(lines))
    return report


__all__ = ("Rate", "summarize", "write_report")
