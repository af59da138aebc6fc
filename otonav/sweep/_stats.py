"""The figures a sweep report is made of: pure functions of the result records.

Pass rates carry a Wilson 95 % score interval (a few hundred runs is too few for the
normal approximation near 0 or 1); percentiles are linear-interpolated (numpy's
default); failure reasons are grouped with their numbers masked, so "ended 0.41 m away"
and "ended 0.52 m away" are one group."""

from __future__ import annotations

import math
import re
from collections import defaultdict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass
from typing import Any

Z95 = 1.959963984540054


@dataclass(frozen=True, slots=True)
class Rate:
    """A pass rate and its Wilson 95 % interval (errors count as not passed)."""

    passed: int
    runs: int
    errors: int
    rate: float | None
    low: float | None
    high: float | None

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)


def wilson(successes: int, n: int, z: float = Z95) -> tuple[float, float]:
    """Wilson score interval for ``successes`` out of ``n`` (n > 0)."""
    if n <= 0:
        raise ValueError("wilson: n must be > 0")
    p = successes / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    # Exact at the ends: k = 0 gives 0 and k = n gives 1 in exact arithmetic; in floats
    # centre - half came out at 1.7e-18 for 0/145.
    low = 0.0 if successes == 0 else max(0.0, centre - half)
    high = 1.0 if successes == n else min(1.0, centre + half)
    return low, high


def pass_rate(records: Sequence[dict[str, Any]]) -> Rate:
    n = len(records)
    passed = sum(1 for r in records if r.get("status") == "passed")
    errors = sum(1 for r in records if r.get("status") == "error")
    if n == 0:
        return Rate(0, 0, 0, None, None, None)
    low, high = wilson(passed, n)
    return Rate(passed, n, errors, passed / n, low, high)


def percentile(values: Sequence[float], q: float) -> float:
    """Linear-interpolated percentile, ``q`` in [0, 100] (numpy's default method)."""
    if not values:
        raise ValueError("percentile of no values")
    ordered = sorted(values)
    pos = (len(ordered) - 1) * q / 100.0
    lo = math.floor(pos)
    hi = min(lo + 1, len(ordered) - 1)
    return ordered[lo] + (ordered[hi] - ordered[lo]) * (pos - lo)


def spread(values: Iterable[float | None]) -> dict[str, float | int | None]:
    """p50, p95, max (and min, count) of the values that exist."""
    present = [v for v in values if v is not None]
    if not present:
        return {"count": 0, "p50": None, "p95": None, "max": None, "min": None}
    return {
        "count": len(present),
        "p50": percentile(present, 50),
        "p95": percentile(present, 95),
        "max": max(present),
        "min": min(present),
    }


def group_rates(
    records: Sequence[dict[str, Any]], key: Callable[[dict[str, Any]], str]
) -> dict[str, Rate]:
    groups: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for r in records:
        groups[key(r)].append(r)
    return {k: pass_rate(v) for k, v in groups.items()}


def override_rates(records: Sequence[dict[str, Any]]) -> dict[str, dict[str, Rate]]:
    """key -> value -> pass rate of the runs with that override value."""
    keys = sorted({k for r in records for k in r.get("overrides", {})})
    return {
        key: group_rates(
            [r for r in records if key in r.get("overrides", {})],
            lambda r, key=key: str(r["overrides"][key]),  # type: ignore[misc]
        )
        for key in keys
    }


_PARENS = re.compile(r"\s*\([^()]*\)")
_NUMBER = re.compile(r"-?\d+(\.\d+)?(e-?\d+)?")


def reason_class(reason: str) -> str:
    """A failure reason with details and numbers masked, and without the recoveries the
    run tried (their list differs from run to run: three failures made three groups,
    issue 39): the group it belongs to."""
    masked = _NUMBER.sub("#", _PARENS.sub("", reason.partition("recoveries:")[0]))
    return "; ".join(part.strip() for part in masked.split(";") if part.strip())


def failures_by_reason(records: Sequence[dict[str, Any]]) -> dict[str, list[dict[str, Any]]]:
    """Reason group -> the runs that failed (or errored) that way, biggest group first."""
    groups: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for r in records:
        if r.get("status") != "passed":
            prefix = "error: " if r.get("status") == "error" else ""
            groups[prefix + reason_class(str(r.get("reason", "")))].append(r)
    return dict(sorted(groups.items(), key=lambda kv: (-len(kv[1]), kv[0])))
