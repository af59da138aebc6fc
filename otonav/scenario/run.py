"""Run a scenario on a virtual-time loop driven by the physics world, judge it, and
leave its artifacts: the recording (always finished, whatever ends the run), the
trajectory plot."""

from __future__ import annotations

import asyncio
import contextlib
import importlib
import json
import math
import signal
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import Any

from otonav import limits
from otonav._version import __version__
from otonav.actors import topics
from otonav.hal import RobotHardwareInterface
from otonav.hal.types import Reach
from otonav.msgs import Header, Point, Pose, PoseStamped, ScenarioVerdict, Time
from otonav.record.diskfull import DiskFullError, is_disk_full
from otonav.record.outlock import lock_output
from otonav.record.writer import RecordingWriter
from otonav.runtime import (
    LATCHED_QOS,
    Actor,
    ActorCrashedError,
    RealTime,
    SimTimeoutError,
    System,
    TimeMode,
    Virtual,
    until,
    virtual_loop_factory,
)
from otonav.runtime._asyncio_compat import preload_anyio_backend
from otonav.scenario.config import ScenarioConfig
from otonav.scenario.crash import RunCrashedError, crash_reason
from otonav.scenario.judge import Judge
from otonav.scenario.plot import key_poses, plot_trajectory
from otonav.scenario.validate import check_cost, check_goal
from otonav.stack import StackConfig, build_actors, build_world
from otonav.stack.config import NavConfig
from otonav.stack.robot import describe_robot, reached, slower
from otonav.stack.session import StackSession

VERDICT_TOPIC = "/scenario/verdict"
RUN_METADATA = "otonav"
LAZY_IMPORTS = ("numpy.ma",)
"""Modules a process's first run would otherwise import inside its timed span, with
anyio's asyncio backend (when the loop starts; :func:`preload_lazy_imports`): numpy.ma
(numpy imports it at the first ``np.unique``, in the navigator's map). 25-110 ms on this
machine: imports, not the run, so they load before the summary's wall clock starts (ADR
0027)."""


def preload_lazy_imports() -> None:
    """Import :data:`LAZY_IMPORTS` and anyio's asyncio backend now."""
    preload_anyio_backend()
    for module in LAZY_IMPORTS:
        importlib.import_module(module)


@dataclass(frozen=True, slots=True)
class Verdict:
    """The outcome of a scenario run (sim figures are from ground truth)."""

    scenario: str
    passed: bool
    reached: bool
    reason: str
    time_to_goal_s: float | None
    min_clearance_m: float
    final_distance_m: float
    path_length_m: float
    sim_time_s: float
    wall_time_s: float
    rtf: float
    recording: str | None = None
    plot: str | None = None
    expect: str = "reached"
    """The scenario's expected outcome: ``reached`` or ``unreachable``."""
    unreachable_at_s: float | None = None
    """s of sim time when the navigator reported the goal unreachable; None if never."""
    nav_state: str = ""
    """The navigator's last /nav/state (e.g. reached, unreachable)."""
    nav_reason: str = ""
    """The navigator's last reason (/nav/diagnostics), e.g. why it gave up."""
    recoveries: list[str] = field(default_factory=list)
    """The recovery rungs the navigator ran, in order, each with when and why (e.g.
    ``spin at 12.3 s (rung 1/3, under 0.3 m of progress along the path in 3.5 s)``);
    the reason names them too."""
    sim_budget_s: float = 0.0
    """s of sim time the scenario allowed (scaled to the robot's speed: ``for_robot``)."""
    clearance_floor_m: float = 0.0
    """m: the scenario's ``min_clearance``, the floor ``min_clearance_m`` is judged on."""
    closest_xy: list[float] | None = None
    """[x, y] where the robot came closest to an obstacle (world frame, m; a list, as it
    reads back from JSON); None if nowhere."""
    robot: dict[str, Any] = field(default_factory=dict)
    """The robot as run: model, top speeds, the geometry values and where each came
    from (:func:`robot_summary`)."""

    def as_dict(self) -> dict[str, object]:
        return asdict(self)


def otonav_version() -> str:
    """The version recorded with a run: the code's (otonav/_version.py), never the
    installed metadata on disk, which a reinstall can hide for a moment."""
    return __version__


BUDGET_SPEED = 0.4
"""m/s: scenario budgets are written for a robot that drives this fast (otonav's robot
under the default ``nav.max_v``). A robot whose description states a lower top speed
(``robot.max_v``; the ``burger``'s 0.22 m/s) gets every budget scaled by BUDGET_SPEED /
its top speed, so the same courses judge it fairly (ADR 0041)."""


def for_robot(
    scenario: ScenarioConfig, stack: StackConfig, reach: Reach | None = None
) -> ScenarioConfig:
    """``scenario`` as run with ``stack``'s robot: its sim budget scaled to the robot's
    stated top speed, or to the one it really reaches or its control range allows
    (``reach``, ADR 0066), when that is below :data:`BUDGET_SPEED`."""
    top = describe_robot(stack.robot).max_v
    if reach is not None:  # what it reaches, or may be asked (its control range)
        real = reach.v if slower(reach) < 1.0 else reach.asked_v
        top = min(top, real) if top is not None else real
    if top is None or top >= BUDGET_SPEED:
        return scenario
    budget = min(scenario.sim_budget * BUDGET_SPEED / top, limits.MAX_SIM_BUDGET_S)
    return scenario.model_copy(update={"sim_budget": round(budget, 3)})


def scenario_world(
    scenario: ScenarioConfig, stack: StackConfig, *, source: str = "scenario"
) -> tuple[ScenarioConfig, StackConfig, RobotHardwareInterface]:
    """The scenario as run with the stack's robot (:func:`for_robot`), the stack config
    with the scenario's scene, and its world with the scenario's obstacles and start
    pose, checked: a goal or start outside the arena or on an obstacle raises
    ``ConfigFileError`` naming ``source`` (the world is then closed)."""
    stack = effective_stack(scenario, stack)
    hal = build_world(
        stack,
        extra_obstacles=[b.to_obstacle() for b in scenario.obstacles],
        start=scenario.start.as_tuple(),
    )
    try:
        scenario = for_robot(scenario, stack, reached(stack, hal))
        check_goal(scenario, stack.world.scene, hal.obstacles(), hal.walls(), source=source)
        check_cost(scenario, stack, len(hal.obstacles() + hal.walls()), source=source)
    except BaseException:
        hal.close()
        raise
    return scenario, stack, hal


def finite_figures(figures: dict[str, Any]) -> dict[str, Any]:
    """JSON has no Infinity or NaN: a figure that is not finite becomes null."""
    return {
        k: None if isinstance(v, float) and not math.isfinite(v) else v for k, v in figures.items()
    }


def effective_stack(scenario: ScenarioConfig, stack: StackConfig) -> StackConfig:
    """The stack config with the scenario's scene, if it names one, and the navigator's
    goal tolerance following the scenario's (half of it, never below ``nav.tolerance``'s
    default) unless ``nav.tolerance`` is set (issue 42, ADR 0079)."""
    updates: dict[str, Any] = {}
    if scenario.scene is not None:
        updates["world"] = stack.world.model_copy(update={"scene": scenario.scene})
    default = NavConfig().tolerance
    if stack.nav.tolerance == default and scenario.goal_tolerance / 2 > default:
        updates["nav"] = stack.nav.model_copy(update={"tolerance": scenario.goal_tolerance / 2})
    return stack.model_copy(update=updates) if updates else stack


def scenario_session(
    scenario: ScenarioConfig,
    stack: StackConfig,
    hal: RobotHardwareInterface,
    judge: Judge,
    *,
    extra_actors: tuple[Actor, ...] = (),
    time: TimeMode = Virtual(),
    recording: Path | None = None,
) -> StackSession:
    """The session of a scenario run in ``time``: the recorder (with ``recording``), the
    extra actors, the robot stack starting at the scenario's start pose, and the judge."""
    try:
        robot = build_actors(stack, hal, initial_pose=scenario.start.as_tuple())
    except BaseException:
        hal.close()
        raise
    session = StackSession(hal, [*extra_actors, *robot, judge], time=time, record_to=recording)
    if session.writer is not None:
        session.writer.add_metadata(RUN_METADATA, run_metadata(scenario, stack))
    return session


async def drive(session: StackSession, scenario: ScenarioConfig, judge: Judge) -> None:
    """Run ``session`` (not closing it): publish the goal on /goal, then wait in sim time
    until the judge is done or the budget is spent (a verdict, not an error)."""
    async with session.running(close=False) as system:
        goal = system.publisher(topics.GOAL, PoseStamped, LATCHED_QOS, name="scenario")
        await goal.publish(
            PoseStamped(
                header=Header(stamp=Time.from_seconds(system.clock.now()), frame_id="odom"),
                pose=Pose(position=Point(x=scenario.goal.x, y=scenario.goal.y)),
            )
        )
        # Running out of budget is a verdict (judged below), not an error. The run also
        # ends when the navigator gives up (/nav/state ``unreachable``): whether that
        # passes depends on the scenario's ``expect``.
        with contextlib.suppress(SimTimeoutError):
            await until(
                lambda: judge.finished or judge.entered,
                within=scenario.sim_budget,
                observe=lambda: f"{judge.distance:.3f} m from the goal",
                what=f"reaching the goal within {scenario.goal_tolerance} m",
            )
        if judge.entered and not judge.finished:
            # Entering the tolerance is not arriving: the judge checks settle_s later
            # (past the budget if need be) that the robot stopped there.
            with contextlib.suppress(SimTimeoutError):
                await until(
                    lambda: judge.finished,
                    within=judge.settle_s + 2.0 / judge.rate_hz,
                    what="the arrival check",
                )


async def _main(
    scenario: ScenarioConfig,
    session: StackSession,
    judge: Judge,
    on_start: Callable[[asyncio.AbstractEventLoop, asyncio.Task[None]], None] | None,
) -> None:
    with run_task(on_start):
        await drive(session, scenario, judge)


@contextlib.contextmanager
def run_task(
    on_start: Callable[[asyncio.AbstractEventLoop, asyncio.Task[None]], None] | None,
) -> Iterator[None]:
    """The current task is a scenario run: hand it to ``on_start`` (a host that may
    cancel it), and let SIGTERM end it like Ctrl-C does (asyncio.Runner handles SIGINT):
    by cancellation, so every finally runs and the recording is finished."""
    loop = asyncio.get_running_loop()
    task = asyncio.current_task()
    if on_start is not None and task is not None:
        on_start(loop, task)
    # Only over the default handler (asyncio.Runner's rule for SIGINT): a host that
    # handles SIGTERM itself (the CLI) keeps its handler. Cancel once: a second
    # SIGTERM must not cancel the shutdown's own awaits.
    own = (
        threading.current_thread() is threading.main_thread()
        and task is not None
        and signal.getsignal(signal.SIGTERM) == signal.SIG_DFL
    )
    if own and task is not None:
        loop.add_signal_handler(signal.SIGTERM, _cancel_once, task)
    try:
        yield
    finally:
        if own:
            loop.remove_signal_handler(signal.SIGTERM)


def _cancel_once(task: asyncio.Task[Any]) -> None:
    if not task.cancelling():
        task.cancel()


@contextlib.contextmanager
def opened_scenario(
    scenario: ScenarioConfig,
    stack: StackConfig,
    out_dir: Path | None,
    record: bool,
    source: str,
    progress: Callable[[Judge, float], None] | None,
    extra_actors: tuple[Actor, ...],
    time: TimeMode = Virtual(),
    on_system: Callable[[System], None] | None = None,
) -> Iterator[tuple[ScenarioConfig, StackConfig, RobotHardwareInterface, Judge, StackSession]]:
    """What a judged run opens, in the virtual and the real-time runner alike: the lock
    on ``out_dir`` (held until the block ends: one run per out_dir, issue 27, refused
    before it touches a file), the world, the judge and the session recording to
    ``out_dir/recording.mcap`` (with ``record``); ``on_system(system)`` is called with the
    session's wired system before it runs (the session is closed if it raises)."""
    with lock_output(out_dir) if out_dir is not None else contextlib.nullcontext():
        scenario, stack, hal = scenario_world(scenario, stack, source=source)
        judge = Judge(
            hal,
            (scenario.goal.x, scenario.goal.y),
            scenario.goal_tolerance,
            progress=progress,
            nav_must_say_reached=stack.nav.planner != "external",
            arrival=scenario.arrival,
        )
        session = scenario_session(
            scenario,
            stack,
            hal,
            judge,
            time=time,
            extra_actors=extra_actors,
            recording=out_dir / "recording.mcap" if out_dir and record else None,
        )
        if on_system is not None:
            try:
                on_system(session.system)
            except BaseException:
                session.close()
                raise
        yield scenario, stack, hal, judge, session


def run_scenario(
    scenario: ScenarioConfig = ScenarioConfig(),
    stack: StackConfig = StackConfig(),
    *,
    out_dir: Path | None = None,
    record: bool = True,
    plot: bool = True,
    wall_ceiling: float | None = 300.0,
    extra_actors: tuple[Actor, ...] = (),
    on_start: Callable[[asyncio.AbstractEventLoop, asyncio.Task[None]], None] | None = None,
    source: str = "scenario",
    progress: Callable[[Judge, float], None] | None = None,
    time: TimeMode = Virtual(),
    gui: bool = False,
    hold: Callable[[Verdict], None] | None = None,
    on_system: Callable[[System], None] | None = None,
) -> Verdict:
    """Run ``scenario`` headless in virtual time and judge it. With ``out_dir``, leave
    ``recording.mcap`` (unless ``record=False``) and ``trajectory.png`` there. The
    recording is finished on every exit path (an exception, Ctrl-C, SIGTERM).
    ``extra_actors`` join the system (monitors, fault injectors). ``on_system(system)``
    is called with the run's wired :class:`~otonav.runtime.System` before it starts: a
    host reaching the actors (``otonav run --foxglove`` serves their parameters).
    ``progress(judge, sim_time)`` is called after every judge sample (the CLI's progress
    line). ``on_start(loop, task)`` is called on the run's loop as it starts: a host
    running this in a worker thread cancels the run with
    ``loop.call_soon_threadsafe(task.cancel)``. A goal outside the arena or on an
    obstacle raises ``ConfigFileError`` naming ``source``.
    Another run writing to ``out_dir`` raises :class:`~otonav.record.outlock.OutputBusyError`
    before anything is touched. An actor's crash raises
    :class:`~otonav.scenario.crash.RunCrashedError` once the artifacts are written: an
    ``ActorCrashedError`` carrying the failed verdict. A full disk stops the run and
    raises :class:`~otonav.record.diskfull.DiskFullError` naming the file, once the
    recording is closed (readable) and the world too.

    ``time=RealTime(scale)`` paces sim time to the wall clock times ``scale`` instead (the
    same actors, judge and artifacts; ``wall_ceiling`` does not apply); ``gui=True`` (real
    time, scale 1 unless given) shows the run in MuJoCo's viewer, and ``hold(verdict)``
    keeps its window open at the end: see
    :func:`~otonav.scenario.realtime.run_scenario_realtime`."""
    if isinstance(time, RealTime) or gui:
        from otonav.scenario.realtime import run_scenario_realtime

        return run_scenario_realtime(
            scenario,
            stack,
            out_dir=out_dir,
            record=record,
            plot=plot,
            time=time if isinstance(time, RealTime) else RealTime(),
            gui=gui,
            on_start=on_start,
            extra_actors=tuple(extra_actors),
            hold=hold,
            source=source,
            progress=progress,
            on_system=on_system,
        )
    if hold is not None:
        raise ValueError("run_scenario: hold= needs gui=True (it keeps the viewer open)")
    with opened_scenario(
        scenario,
        stack,
        out_dir,
        record,
        source,
        progress,
        tuple(extra_actors),
        on_system=on_system,
    ) as (scenario, stack, hal, judge, session):
        preload_lazy_imports()
        sim_time = [0.0]

        def run() -> None:
            # The session makes the world the loop's time source when the run starts.
            factory = virtual_loop_factory(wall_ceiling=wall_ceiling)
            with asyncio.Runner(loop_factory=factory) as runner:
                try:
                    runner.run(_main(scenario, session, judge, on_start))
                finally:
                    sim_time[0] = runner.get_loop().time()

        return judged_run(
            JudgedRun(scenario, stack, hal, judge, session, out_dir, plot),
            run,
            lambda: sim_time[0],
        )


@dataclass(frozen=True, slots=True)
class JudgedRun:
    """What a judged run is made of, for :func:`judged_run`."""

    scenario: ScenarioConfig
    stack: StackConfig
    hal: RobotHardwareInterface
    judge: Judge
    session: StackSession
    out_dir: Path | None
    plot: bool


def judged_run(
    parts: JudgedRun,
    run: Callable[[], None],
    sim_time: Callable[[], float],
    *,
    amend: Callable[[Verdict], Verdict] | None = None,
) -> Verdict:
    """``run()`` the scenario, then judge it and tear it down, whatever ended it: the
    verdict (failed with "run ended early (...)" if ``run`` raised; ``amend(verdict)``
    may change one that completed), appended to the recording, the plot drawn, the
    session closed. An actor's crash raises :class:`RunCrashedError` carrying the
    verdict, once the artifacts are written; any other exception propagates after them.
    ``sim_time()`` is the run's sim time (after ``run`` returned or raised). The one
    ending of every judged runner (virtual and real time)."""
    scenario, stack, hal, judge, session = (
        parts.scenario,
        parts.stack,
        parts.hal,
        parts.judge,
        parts.session,
    )
    wall_start = time.perf_counter()
    ended = "completed"
    crash: ActorCrashedError | None = None
    try:
        run()
    except ActorCrashedError as exc:  # a verdict still (below), raised with it
        crash, ended = exc, f"ActorCrashedError: {crash_reason(exc)}"
    except BaseException as exc:
        ended = f"{type(exc).__name__} at sim time {sim_time():.3f} s: {exc}"
        ended = ended.strip().rstrip(":")
        raise
    finally:
        wall = time.perf_counter() - wall_start
        try:
            verdict = judge_verdict(
                scenario, judge, sim_time(), wall, robot=robot_summary(stack, hal)
            )
            if ended != "completed":
                verdict = replace(verdict, passed=False, reason=f"run ended early ({ended})")
            elif amend is not None:
                verdict = amend(verdict)
            verdict = save_artifacts(
                verdict, scenario, stack, judge, session, parts.out_dir, parts.plot
            )
        finally:
            session.close()  # idempotent: reached even if the verdict or plot failed
    if crash is not None:
        raise RunCrashedError(crash, verdict) from crash.__cause__
    return verdict


TITLE_REASON_WIDTH = 64
"""Characters per line of the verdict's reason in a plot's title (two lines at most)."""


def verdict_title(scenario: str, passed: bool, reason: str) -> str:
    """A plot's title that tells the verdict: the scenario, PASSED or FAILED, and why."""
    import textwrap

    why = textwrap.wrap(reason, TITLE_REASON_WIDTH, max_lines=2, placeholder=" …")
    return "\n".join([f"{scenario}: {'PASSED' if passed else 'FAILED'}", *why])


def save_artifacts(
    verdict: Verdict,
    scenario: ScenarioConfig,
    stack: StackConfig,
    judge: Judge,
    session: StackSession,
    out_dir: Path | None,
    plot: bool,
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
    if out_dir is not None and plot:
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


def robot_summary(stack: StackConfig, hal: RobotHardwareInterface) -> dict[str, Any]:
    """What the verdict says about the robot: which model, its top speeds, each
    geometry value and where it came from (derived from the model, or given)."""
    robot = describe_robot(stack.robot)
    g = hal.geometry
    return {
        "model": robot.label,
        "max_v": robot.max_v,
        "max_omega": robot.max_omega,
        "wheel_radius": g.wheel_radius,
        "wheel_separation": g.wheel_separation,
        "footprint_radius": g.footprint_radius,
        "laser_offset": [g.laser_offset_x, g.laser_offset_z],
        "reach": asdict(reach) if (reach := reached(stack, hal)) is not None else None,
        "sources": hal.geometry_sources(),
        "warnings": lidar_over_obstacles(hal),
    }


def lidar_over_obstacles(hal: RobotHardwareInterface) -> list[str]:
    """A lidar above the tallest obstacle sees none of them (issue 38): a warning."""
    g, top = hal.geometry, hal.tallest_obstacle()
    height = g.base_height + g.laser_offset_z
    if top is None or height < top:
        return []
    return [
        f"warning: the lidar is {height:.2f} m above the floor, over the tallest obstacle "
        f"({top:.2f} m): it sees none of them; mount it lower (robot.lidar)"
    ]


def judge_verdict(
    scenario: ScenarioConfig,
    judge: Judge,
    sim_time: float,
    wall: float,
    *,
    robot: dict[str, Any] | None = None,
) -> Verdict:
    """Pass when the scenario's expected outcome happened (``expect``: the goal reached,
    or the navigator's ``unreachable`` inside the budget) and the clearance held."""
    unmeasured = judge.clearance_problem
    clear = judge.min_clearance >= scenario.min_clearance and unmeasured is None
    gave_up = judge.unreachable_at is not None and judge.unreachable_at <= scenario.sim_budget
    reasons = []
    if scenario.expect == "reached":
        outcome = judge.reached
        if judge.arrival_problem is not None:
            reasons.append(judge.arrival_problem)
        elif not judge.reached:
            why = (
                f"the navigator reported the goal unreachable at {judge.unreachable_at:.1f} s"
                + (f" ({judge.nav_reason})" if judge.nav_reason else "")
                if judge.unreachable_at is not None
                else f"did not reach the goal within {scenario.sim_budget:g} s"
            )
            reasons.append(
                f"{why} (ended {judge.distance:.3f} m away; tolerance {scenario.goal_tolerance} m)"
            )
    else:
        outcome = gave_up and not judge.reached
        if judge.reached:
            reasons.append("reached a goal that was expected to be unreachable")
        elif not gave_up:
            reasons.append(
                f"the navigator did not report the goal unreachable within "
                f"{scenario.sim_budget:g} s (last state: {judge.nav_state})"
            )
    if judge.hardware_fault is not None and not judge.reached:
        outcome = False
        reasons[:] = [judge.hardware_fault]
    elif not outcome and (health := judge.hal.health()).faulted:
        # A fault that outlasted the run (e.g. encoder data late the whole time).
        reasons.append(
            f"hardware fault since {health.since:.2f} s: {health.fault}: {health.message}"
        )
    if unmeasured is not None:
        reasons.append(unmeasured)
    elif not clear:
        reasons.append(
            f"came {judge.min_clearance:.3f} m from an obstacle "
            f"(minimum {scenario.min_clearance} m)"
        )
    if not reasons:
        reasons.append(
            "reached the goal with clearance"
            if scenario.expect == "reached"
            else f"reported unreachable at {judge.unreachable_at:.1f} s, as expected, "
            "with clearance"
        )
    reasons.extend(judge.slips)
    reasons.extend((robot or {}).get("warnings", ()))
    if judge.recoveries:
        reasons.append(f"recoveries: {'; '.join(judge.recoveries)}")
    return Verdict(
        scenario=scenario.name,
        passed=outcome and clear,
        reached=judge.reached,
        reason="; ".join(reasons),
        time_to_goal_s=judge.time_to_goal,
        min_clearance_m=judge.min_clearance,
        final_distance_m=judge.distance,
        path_length_m=judge.path_length,
        sim_time_s=sim_time,
        wall_time_s=wall,
        rtf=sim_time / wall if wall > 0 else math.inf,
        expect=scenario.expect,
        unreachable_at_s=judge.unreachable_at,
        nav_state=judge.nav_state,
        nav_reason=judge.nav_reason,
        recoveries=list(judge.recoveries),
        sim_budget_s=scenario.sim_budget,
        clearance_floor_m=scenario.min_clearance,
        closest_xy=list(judge.min_clearance_at) if judge.min_clearance_at else None,
        robot=robot or {},
    )
