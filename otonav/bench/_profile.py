"""Where the time goes: one profiled run, its own time per function grouped into stages.
(cProfile inflates Python-heavy stages; read the shares, not the absolute figures.)"""

from __future__ import annotations

import cProfile
import pstats

from otonav.bench._harness import Case, run_case

# (stage, substring of the function's file or name), first match wins.
STAGES: tuple[tuple[str, str], ...] = (
    ("physics (mj_step)", "mj_step"),
    ("lidar (mj_multiRay)", "mj_multiRay"),
    ("world: sensor reads, HAL", "otonav/hal/"),
    ("message construction (pydantic)", "pydantic"),
    ("encoding (CDR)", "otonav/record/cdr"),
    ("encoding (CDR)", "<cdr encoder of"),  # the generated encoders' pseudo-file
    ("writing (mcap)", "/mcap/"),
    ("recorder + writer glue", "otonav/record/"),
    ("mailboxes + funnel", "otonav/runtime/mailbox"),
    ("mailboxes + funnel", "otonav/runtime/funnel"),
    ("control + nav math", "otonav/control/"),
    ("control + nav math", "otonav/nav/"),
    ("control + nav math", "numpy"),
    ("actors", "otonav/actors/"),
    ("messages (helpers)", "otonav/msgs/"),
    ("event loop + sim clock", "asyncio"),
    ("event loop + sim clock", "otonav/runtime/"),
    ("event loop + sim clock", "anyio"),
)


def stage_of(filename: str, function: str) -> str:
    for stage, needle in STAGES:
        if needle in filename or needle in function:
            return stage
    return "other"


def profile_case(case: Case) -> dict[str, float]:
    """Seconds of own time per stage for one run of ``case`` (in this process)."""
    profiler = cProfile.Profile()
    profiler.enable()
    run_case(case)
    profiler.disable()
    stats = pstats.Stats(profiler)
    totals: dict[str, float] = {}
    for (filename, _line, function), row in stats.stats.items():  # type: ignore[attr-defined]
        own = row[2]
        stage = stage_of(filename, function)
        totals[stage] = totals.get(stage, 0.0) + own
    return dict(sorted(totals.items(), key=lambda kv: -kv[1]))
