"""The clutter curve (issue 30): what a run costs as the world fills with boxes.

One course, the ``box`` course's without its box: the ``empty`` scene, start (-3, 0)
facing +x, goal (3, 0). ``n`` boxes of 0.1 m, seeded, turned at random, anywhere in the
arena except a lane 2 m wide along the straight line (|y| < 1 m), so every run drives
the same path past more and more geometry. Each run is ``otonav run --no-record``: the
summary's RTF (the loop's wall, without building the world or drawing the plot), and
the PNG drawn separately and timed. One cProfile run per count says what dominates.
"""

from __future__ import annotations

import functools
import random
import statistics
import time
from dataclasses import dataclass, replace
from pathlib import Path
from tempfile import TemporaryDirectory

from otonav.bench._harness import Case, Sample
from otonav.hal import BoxObstacle
from otonav.scenario._config import BoxSpec, GoalSpec, ScenarioConfig, StartSpec

COUNTS = (0, 100, 300, 1000, 3000)
"""Boxes per world on the curve."""
LANE_HALF_WIDTH = 1.0
"""m: no box centre within this of the line y = 0 (the robot's way, kept clear)."""
BOX_SIZE = 0.1
"""m: each box's side."""
_ARENA = 4.8
"""m: box centres within |x|, |y| <= this (the empty scene's walls are at 5 m)."""


def clutter_scenario(boxes: int, seed: int = 30) -> ScenarioConfig:
    """The course with ``boxes`` boxes off the robot's lane (the same boxes for a seed:
    the first ``n`` of a longer list are the world with ``n``)."""
    rng = random.Random(seed)
    specs: list[BoxSpec] = []
    while len(specs) < boxes:
        x, y = rng.uniform(-_ARENA, _ARENA), rng.uniform(-_ARENA, _ARENA)
        yaw = rng.uniform(-3.14, 3.14)
        if abs(y) < LANE_HALF_WIDTH:
            continue
        specs.append(
            BoxSpec(
                x=round(x, 4), y=round(y, 4), size_x=BOX_SIZE, size_y=BOX_SIZE, yaw=round(yaw, 4)
            )
        )
    return ScenarioConfig(
        name=f"clutter-{boxes}",
        scene="empty",
        obstacles=tuple(specs),
        start=StartSpec(x=-3.0, y=0.0, yaw=0.0),
        goal=GoalSpec(x=3.0, y=0.0),
        sim_budget=60.0,
    )


def _plot(boxes: tuple[BoxObstacle, ...]) -> float:
    """Wall seconds to draw and write the PNG of a run in this world, as a run draws it
    (a straight path: the figure's cost is the boxes, not the path)."""
    from otonav.scenario._plot import plot_trajectory

    path = [(0.01 * k, -3.0 + 0.003 * k, 0.0) for k in range(2001)]
    with TemporaryDirectory() as tmp:
        t = time.perf_counter()
        plot_trajectory(Path(tmp) / "t.png", path, boxes, (3.0, 0.0), 0.15, (0.0, 1.0), "x")
        return time.perf_counter() - t


@functools.cache
def warm_up() -> None:
    """What a process's first run pays once and a second does not (matplotlib and its
    fonts, the lazy imports): paid here, outside every figure."""
    from otonav.scenario._judged import preload_lazy_imports

    preload_lazy_imports()
    _plot(())


def run_clutter(case: Case) -> Sample:
    """One run of the course with ``case.boxes`` boxes, as ``otonav run --no-record``
    runs it: ``wall_s`` and ``cpu_s`` from the loop's start to the verdict; phases: the
    summary's RTF, the wall outside the loop (world build, checks) and the plot's."""
    import resource

    from otonav.scenario._run import run_scenario
    from otonav.stack import StackConfig

    warm_up()
    scenario = clutter_scenario(case.boxes)
    marks: list[tuple[float, float]] = []
    wall0 = time.perf_counter()
    verdict = run_scenario(
        scenario,
        StackConfig(),
        out_dir=None,
        record=False,
        plot=False,
        on_start=lambda _loop, _task: marks.append((time.perf_counter(), time.process_time())),
    )
    end = (time.perf_counter(), time.process_time())
    if not verdict.passed:
        raise RuntimeError(f"clutter bench: {scenario.name} failed: {verdict.reason}")
    plot_s = _plot(tuple(b.to_obstacle() for b in scenario.obstacles))
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    ((start_wall, start_cpu),) = marks
    return Sample(
        end[0] - start_wall,
        verdict.sim_time_s,
        rss,
        end[1] - start_cpu,
        (
            ("summary_rtf", verdict.rtf),
            ("plot_s", plot_s),
            ("setup_s", start_wall - wall0),
        ),
    )


# What dominates: the profile's own time grouped (first match wins), before the general
# stages of otonav.bench._profile.
CLUTTER_STAGES: tuple[tuple[str, str], ...] = (
    ("judge (clearance)", "otonav/scenario/clearance"),
    ("judge (clearance)", "otonav/scenario/judge"),
    ("physics (mj_step, mj_forward)", "mj_step"),
    ("physics (mj_step, mj_forward)", "mj_forward"),
    ("lidar (mj_multiRay)", "mj_multiRay"),
    ("lidar (numpy caster)", "otonav/hal/raycast"),
    ("world build (MjSpec, compile)", "compile"),
    ("world build (MjSpec, compile)", "add_geom"),
    ("world build (MjSpec, compile)", "pydantic"),
    ("plot (matplotlib)", "matplotlib"),
    ("plot (matplotlib)", "PIL"),
    ("plot (matplotlib)", "Imaging"),
)


def profile_clutter(boxes: int) -> dict[str, float]:
    """Seconds of own time per stage in one profiled run with ``boxes`` boxes."""
    import cProfile
    import pstats

    from otonav.bench._profile import stage_of

    warm_up()
    profiler = cProfile.Profile()
    profiler.enable()
    run_clutter(Case("clutter", boxes=boxes))
    profiler.disable()
    totals: dict[str, float] = {}
    for (filename, _line, function), row in pstats.Stats(profiler).stats.items():  # type: ignore[attr-defined]
        stage = next(
            (s for s, needle in CLUTTER_STAGES if needle in filename or needle in function),
            None,
        ) or stage_of(filename, function)
        totals[stage] = totals.get(stage, 0.0) + row[2]
    return dict(sorted(totals.items(), key=lambda kv: -kv[1]))


@dataclass(frozen=True, slots=True)
class ClutterRow:
    boxes: int
    sim_s: float
    rtf: float
    """Median of the summaries' RTF (``otonav run`` prints it)."""
    rtf_min: float
    rtf_max: float
    rtf_vs_none: float
    """This RTF over the RTF with no boxes, medians of the same session."""
    cpu_rtf: float
    """Sim seconds per CPU second of the loop, median (steadier on a shared machine)."""
    cpu_vs_none: float
    plot_s: float
    setup_s: float
    """Median wall before the loop: building the world (MJCF with the boxes), checks."""
    top: tuple[tuple[str, float], ...] = ()
    """The profile's largest stages, share of the profiled run."""


def clutter_curve(
    counts: tuple[int, ...], reps: int, *, profile: bool, fresh: bool = True
) -> list[ClutterRow]:
    """Each count ``reps`` times, interleaved (0, 100, ..., 0, 100, ...), each run in a
    fresh child process (``fresh`` False: one child for all); with ``profile``, one more
    profiled run per count."""
    from otonav.bench._harness import run_in_children

    cases = [Case("clutter", boxes=n) for _ in range(reps) for n in counts]
    samples = run_in_children(cases, run_clutter, fresh=fresh)
    profiles: dict[int, dict[str, float]] = {}
    if profile:
        import multiprocessing

        with multiprocessing.get_context("spawn").Pool(1, maxtasksperchild=1) as pool:
            profiles = dict(
                zip(counts, pool.map(profile_clutter, counts, chunksize=1), strict=True)
            )
    rows: list[ClutterRow] = []
    for n in counts:
        mine = [s for c, s in zip(cases, samples, strict=True) if c.boxes == n]
        rtfs = [dict(s.phases)["summary_rtf"] for s in mine]
        stages = profiles.get(n, {})
        total = sum(stages.values()) or 1.0
        rows.append(
            ClutterRow(
                boxes=n,
                sim_s=mine[0].sim_s,
                rtf=statistics.median(rtfs),
                rtf_min=min(rtfs),
                rtf_max=max(rtfs),
                rtf_vs_none=0.0,
                cpu_rtf=statistics.median(s.sim_s / s.cpu_s for s in mine),
                cpu_vs_none=0.0,
                plot_s=statistics.median(dict(s.phases)["plot_s"] for s in mine),
                setup_s=statistics.median(dict(s.phases)["setup_s"] for s in mine),
                top=tuple((k, v / total) for k, v in list(stages.items())[:4]),
            )
        )
    none = next((r for r in rows if r.boxes == 0), None)
    if none is not None:
        rows = [
            replace(r, rtf_vs_none=r.rtf / none.rtf, cpu_vs_none=r.cpu_rtf / none.cpu_rtf)
            for r in rows
        ]
    return rows


def format_clutter(rows: list[ClutterRow], reps: int) -> str:
    if not rows:
        return ""
    lines = [
        f"clutter curve: the box course without its box ({rows[0].sim_s:.1f} s of sim), "
        f"N boxes of {BOX_SIZE:g} m off a {2 * LANE_HALF_WIDTH:g} m lane, --no-record, "
        f"median of {reps} runs each (interleaved)",
        f"{'boxes':>6}{'RTF':>8}{'min':>7}{'max':>7}{'vs 0':>7}{'CPU RTF':>9}{'vs 0':>7}"
        f"{'setup s':>9}{'plot s':>8}",
    ]
    for r in rows:
        lines.append(
            f"{r.boxes:>6}{r.rtf:>7.1f}x{r.rtf_min:>6.1f}x{r.rtf_max:>6.1f}x"
            f"{r.rtf_vs_none:>7.2f}{r.cpu_rtf:>8.1f}x{r.cpu_vs_none:>7.2f}"
            f"{r.setup_s:>9.3f}{r.plot_s:>8.3f}"
        )
    if any(r.top for r in rows):
        lines.append("what dominates (one cProfile run per count, own time, largest four):")
        for r in rows:
            top = ", ".join(f"{name} {100 * share:.0f} %" for name, share in r.top)
            lines.append(f"{r.boxes:>6}: {top}")
    return "\n".join(lines)
