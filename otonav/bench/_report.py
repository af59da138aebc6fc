"""``otonav bench``: (a) bare loop (the stack's own functions inline), (a0) the old bare
loop (ADR 0025's control law), (b) stack, (c) stack + recorder; medians, ratios, peak
RSS, where the time goes, and how cost scales with beams and /scan subscribers."""

from __future__ import annotations

import json
import statistics
from dataclasses import asdict, dataclass
from pathlib import Path

from otonav.bench._harness import Case, Sample, run_in_children

LABELS = {
    "bare0": "(a0) bare loop, old law",
    "bare": "(a) bare loop",
    "stack": "(b) stack, no recorder",
    "recorded": "(c) stack + recorder",
}


@dataclass(frozen=True, slots=True)
class Row:
    label: str
    duration_s: float
    reps: int
    wall_median_s: float
    wall_min_s: float
    wall_max_s: float
    rtf: float
    us_per_10ms_sim: float
    peak_rss_mb: float
    cpu_median_s: float = 0.0


def _row(label: str, samples: list[Sample]) -> Row:
    walls = [s.wall_s for s in samples]
    median = statistics.median(walls)
    sim = samples[0].sim_s
    return Row(
        label,
        sim,
        len(samples),
        median,
        min(walls),
        max(walls),
        sim / median,
        median / (sim / 0.01) * 1e6,
        max(s.peak_rss_mb for s in samples),
        statistics.median(s.cpu_s for s in samples),
    )


def _fixed(samples: list[Sample]) -> dict[str, object]:
    """Medians of the fixed-cost runs: the total and each phase (ms)."""
    names = [name for name, _ in samples[0].phases]
    return {
        "total_ms": 1e3 * statistics.median(s.wall_s for s in samples),
        "cpu_ms": 1e3 * statistics.median(s.cpu_s for s in samples),
        "phases_ms": {
            name: 1e3 * statistics.median(dict(s.phases)[name] for s in samples) for name in names
        },
        "peak_rss_mb": max(s.peak_rss_mb for s in samples),
    }


def _scenario(samples: list[Sample]) -> dict[str, object]:
    rtfs = [dict(s.phases)["summary_rtf"] for s in samples]
    return {
        "summary_rtf_median": statistics.median(rtfs),
        "summary_rtf_min": min(rtfs),
        "summary_rtf_max": max(rtfs),
        "sim_s": samples[0].sim_s,
        "cpu_rtf_median": statistics.median(s.sim_s / s.cpu_s for s in samples if s.cpu_s > 0),
        "peak_rss_mb": max(s.peak_rss_mb for s in samples),
    }


def run_bench(
    duration: float,
    reps: int,
    *,
    scaling: bool,
    profile: bool,
    clutter: tuple[tuple[int, ...], int] | None = None,
    fresh: bool = True,
) -> dict[str, object]:
    """The stack against bare physics (rows, ratios, fixed costs, the acceptance run),
    then with ``scaling`` the beams and subscribers tables, with ``clutter`` (counts,
    reps) the clutter curve (otonav.bench._clutter; profiled per count with ``profile``),
    all in this one session; ``fresh`` False: all in one child (harness.run_in_children)."""
    kinds = ("bare0", "bare", "stack", "recorded")
    extra = ("fixed", "scenario")
    # Interleave a, b, c, ... a, b, c, ... so slow phases of this shared machine hit all.
    cases = [Case(kind, duration) for _ in range(reps) for kind in (*kinds, *extra)]
    samples = run_in_children(cases, fresh=fresh)
    by_kind = {
        k: [s for c, s in zip(cases, samples, strict=True) if c.kind == k] for k in (*kinds, *extra)
    }
    rows = {k: _row(LABELS[k], by_kind[k]) for k in kinds}
    base, cpu_base = rows["bare"].wall_median_s, rows["bare"].cpu_median_s or 1.0
    result: dict[str, object] = {
        "duration_s": duration,
        "reps": reps,
        "rows": [asdict(r) for r in rows.values()],
        "ratio_b_over_a": rows["stack"].wall_median_s / base,
        "ratio_c_over_a": rows["recorded"].wall_median_s / base,
        "cpu_ratio_b_over_a": rows["stack"].cpu_median_s / cpu_base,
        "cpu_ratio_c_over_a": rows["recorded"].cpu_median_s / cpu_base,
        # Against ADR 0025's baseline (the old control law inline), for comparison only.
        "cpu_ratio_b_over_a0": rows["stack"].cpu_median_s / (rows["bare0"].cpu_median_s or 1.0),
        "cpu_ratio_c_over_a0": rows["recorded"].cpu_median_s / (rows["bare0"].cpu_median_s or 1.0),
        "fixed_cost": _fixed(by_kind["fixed"]),
        "acceptance_scenario": _scenario(by_kind["scenario"]),
    }
    if profile:
        import multiprocessing

        from otonav.bench._profile import profile_case

        with multiprocessing.get_context("spawn").Pool(1) as pool:
            result["stages_recorded"] = pool.apply(profile_case, (Case("recorded", duration),))
    if scaling:
        scale_reps = max(1, min(reps, 3))
        beam_cases = [
            Case("recorded", duration, beams=b) for _ in range(scale_reps) for b in (36, 360, 1440)
        ]
        sub_cases = [
            Case("recorded", duration, scan_subscribers=n)
            for _ in range(scale_reps)
            for n in (1, 4, 16)
        ]
        beam_samples = run_in_children(beam_cases)
        sub_samples = run_in_children(sub_cases)
        result["scaling_beams"] = {
            str(b): asdict(
                _row(
                    f"{b} beams",
                    [s for c, s in zip(beam_cases, beam_samples, strict=True) if c.beams == b],
                )
            )
            for b in (36, 360, 1440)
        }
        result["scaling_scan_subscribers"] = {
            str(n): asdict(
                _row(
                    f"{n} /scan subscribers",
                    [
                        s
                        for c, s in zip(sub_cases, sub_samples, strict=True)
                        if c.scan_subscribers == n
                    ],
                )
            )
            for n in (1, 4, 16)
        }
    if clutter is not None:
        from otonav.bench._clutter import clutter_curve

        counts, clutter_reps = clutter
        curve = clutter_curve(counts, clutter_reps, profile=profile, fresh=fresh)
        result["clutter"] = {"reps": clutter_reps, "rows": [asdict(r) for r in curve]}
    return result


def format_report(result: dict[str, object]) -> str:
    lines = [
        f"otonav bench: acceptance world, {result['duration_s']:g} s of sim time, "
        f"median of {result['reps']} runs each (interleaved, one process per run)",
        f"{'configuration':<26}{'wall (s)':>10}{'min':>8}{'max':>8}{'RTF':>8}"
        f"{'us/10ms':>10}{'CPU (s)':>9}{'RSS MB':>9}",
    ]
    for r in result["rows"]:  # type: ignore[attr-defined]
        lines.append(
            f"{r['label']:<26}{r['wall_median_s']:>10.3f}{r['wall_min_s']:>8.3f}{r['wall_max_s']:>8.3f}"
            f"{r['rtf']:>7.0f}x{r['us_per_10ms_sim']:>10.0f}{r['cpu_median_s']:>9.3f}"
            f"{r['peak_rss_mb']:>9.0f}"
        )
    lines.append(
        f"ratios (wall): (b)/(a) = {result['ratio_b_over_a']:.2f}   "
        f"(c)/(a) = {result['ratio_c_over_a']:.2f}"
    )
    if "cpu_ratio_c_over_a" in result:
        lines.append(
            f"ratios (CPU):  (b)/(a) = {result['cpu_ratio_b_over_a']:.2f}   "
            f"(c)/(a) = {result['cpu_ratio_c_over_a']:.2f}"
        )
    if "cpu_ratio_c_over_a0" in result:
        lines.append(
            f"  against (a0), the old baseline: (b)/(a0) = {result['cpu_ratio_b_over_a0']:.2f}"
            f"   (c)/(a0) = {result['cpu_ratio_c_over_a0']:.2f}"
        )
    fixed = result.get("fixed_cost")
    if isinstance(fixed, dict):
        lines.append(
            f"fixed cost of a run, no imports (median): {fixed['total_ms']:.1f} ms wall, "
            f"{fixed['cpu_ms']:.1f} ms CPU; per phase, ms wall / CPU:"
        )
        phases = fixed["phases_ms"]
        for name, ms in phases.items():
            if name == "first run in a process":
                lines.append(f"  {'(a first run, lazy imports included:':<34}{ms:>7.1f} ms wall)")
            elif not name.endswith(" (CPU)"):
                lines.append(f"  {name:<34}{ms:>7.1f}{phases[name + ' (CPU)']:>7.1f}")
    acceptance = result.get("acceptance_scenario")
    if isinstance(acceptance, dict):
        lines.append(
            f"acceptance scenario ({acceptance['sim_s']:.1f} s sim, recorded): summary RTF "
            f"{acceptance['summary_rtf_median']:.0f}x median "
            f"({acceptance['summary_rtf_min']:.0f}-{acceptance['summary_rtf_max']:.0f}), "
            f"{acceptance['cpu_rtf_median']:.0f}x per CPU second"
        )
    stages = result.get("stages_recorded")
    if isinstance(stages, dict):
        total = sum(stages.values()) or 1.0
        lines.append("where the time goes in (c) (one cProfile run, own time per stage):")
        for stage, seconds in stages.items():
            lines.append(f"  {stage:<34}{100 * seconds / total:>5.1f} %")
    for key, title in (
        ("scaling_beams", "lidar beams"),
        ("scaling_scan_subscribers", "/scan subscribers"),
    ):
        table = result.get(key)
        if isinstance(table, dict):
            lines.append(f"scaling with {title} (stack + recorder):")
            for name, r in table.items():
                lines.append(
                    f"  {name:>6}: RTF {r['rtf']:>5.0f}x  {r['us_per_10ms_sim']:>6.0f} us/10ms"
                    f"  wall {r['wall_median_s']:.3f} s"
                )
    clutter = result.get("clutter")
    if isinstance(clutter, dict):
        from otonav.bench._clutter import ClutterRow, format_clutter

        rows = [ClutterRow(**{**r, "top": tuple(map(tuple, r["top"]))}) for r in clutter["rows"]]
        lines.append(format_clutter(rows, clutter["reps"]))
        lines.append(
            f"in this session: (b)/(a) = {result['ratio_b_over_a']:.2f}, "
            f"(c)/(a) = {result['ratio_c_over_a']:.2f} (wall); "
            f"(b)/(a) = {result['cpu_ratio_b_over_a']:.2f}, "
            f"(c)/(a) = {result['cpu_ratio_c_over_a']:.2f} (CPU)"
        )
    return "\n".join(lines)


def write_json(result: dict[str, object], path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(result, indent=2) + "\n")
