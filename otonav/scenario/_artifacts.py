"""What a judged run leaves: the verdict appended to its recording (a message and the
``otonav`` metadata record), the trajectory plot, and a full disk said as such."""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from otonav._version import __version__
from otonav.msgs import Header, ScenarioVerdict, Time
from otonav.record._diskfull import DiskFullError, is_disk_full
from otonav.record._writer import RecordingWriter
from otonav.scenario._config import ScenarioConfig
from otonav.scenario._judge import Judge
from otonav.scenario._plot import key_poses, plot_trajectory
from otonav.scenario._verdict import Verdict, finite_figures, verdict_title
from otonav.stack import StackConfig
from otonav.stack._session import StackSession

PlotWhen = bool | Callable[[Verdict], bool]
"""Whether a judged run draws its trajectory plot: always, never, or when the verdict
says so (a sweep draws only the runs it keeps, from the run's own ground truth)."""

VERDICT_TOPIC = "/scenario/verdict"


RUN_METADATA = "otonav"


def otonav_version() -> str:
    """The version recorded with a run: the code's (otonav/_version.py), never the
    installed metadata on disk, which a reinstall can hide for a moment."""
    return __version__


def save_artifacts(
    verdict: Verdict,
    scenario: ScenarioConfig,
    stack: StackConfig,
    judge: Judge,
    session: StackSession,
    out_dir: Path | None,
    plot: PlotWhen,
) -> Verdict:
    """Tear ``session`` down with the verdict appended to its recording, and draw the
    trajectory; the verdict names both files."""
    writer = session.writer
    try:
        session.close(epilogue=lambda writer: _append_verdict(writer, scenario, stack, verdict))
    except DiskFullError:
        if writer is None or writer.failed is None:
            raise
    if writer is not None:
        if writer.failed is not None:  # the disk is full: no plot either
            raise disk_full_stop(writer.failed, verdict.sim_time_s) from writer.failed.cause
        verdict = replace(verdict, recording=str(writer.path))
    if out_dir is not None and (plot(verdict) if callable(plot) else plot):
        png = out_dir / "trajectory.png"
        try:
            plot_trajectory(
                png,
                judge.trajectory,
                judge.boxes + judge.rounds + judge.polygons,
                (scenario.goal.x, scenario.goal.y),
                scenario.goal_tolerance,
                judge.min_clearance_at,
                verdict_title(verdict.scenario, verdict.passed, verdict.reason),
                footprint=judge.hal.geometry.footprint,
                poses=key_poses(judge.trajectory, scenario.start.yaw, judge.min_clearance_at),
            )
        except OSError as exc:
            if not is_disk_full(exc):
                raise
            png.unlink(missing_ok=True)  # a cut-off PNG is no plot
            raise DiskFullError(png, exc, "the plot was not written") from exc
        verdict = replace(verdict, plot=str(png))
    return verdict


def disk_full_stop(error: DiskFullError, sim_time: float) -> DiskFullError:
    """The recording's :class:`DiskFullError`, saying where the run stopped, what was
    kept and how to get an indexed copy (issue 27)."""
    path = error.path
    return error.with_detail(
        f"the run was stopped at sim time {sim_time:.2f} s; {error.detail}: "
        f"'otonav salvage {path} OTHER_DISK/{path.name}' copies it to an indexed file"
    )


def _append_verdict(
    writer: RecordingWriter, scenario: ScenarioConfig, stack: StackConfig, verdict: Verdict
) -> None:
    """The verdict as a message and a metadata record (the session finishes the file)."""
    writer.write(
        VERDICT_TOPIC,
        ScenarioVerdict(
            header=Header(stamp=Time.from_seconds(verdict.sim_time_s)),
            scenario=verdict.scenario,
            passed=verdict.passed,
            reached=verdict.reached,
            reason=verdict.reason,
            time_to_goal=verdict.time_to_goal_s if verdict.time_to_goal_s is not None else -1.0,
            min_clearance=verdict.min_clearance_m,
            final_distance=verdict.final_distance_m,
            path_length=verdict.path_length_m,
            sim_time=verdict.sim_time_s,
            nav_state=verdict.nav_state,
            nav_reason=verdict.nav_reason,
        ),
        verdict.sim_time_s,
    )
    figures = {
        k: v
        for k, v in verdict.as_dict().items()
        if k not in ("wall_time_s", "rtf", "recording", "plot")
    }
    writer.add_metadata(
        RUN_METADATA,
        {
            **run_metadata(scenario, stack),
            "verdict": json.dumps(finite_figures(figures), sort_keys=True, default=str),
        },
    )


def run_metadata(scenario: ScenarioConfig, stack: StackConfig) -> dict[str, str]:
    """The ``otonav`` metadata record of a scenario run, without its verdict. Written
    when the recording opens (a cut-off file keeps it) and again, with the verdict, at
    the end; readers take the last."""
    return {
        "scenario": scenario.name,
        "seed": str(scenario.seed),
        "otonav_version": otonav_version(),
        "scenario_config": scenario.model_dump_json(),
        "stack_config": stack.model_dump_json(),
    }
