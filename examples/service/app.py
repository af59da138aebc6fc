"""otonav inside a web service: a small Starlette app served by uvicorn.

- a live robot (real-time mode, on the service's own loop) opened at startup: its pose
  streams as server-sent events, goals are posted to it;
- simulations on request: each run is a scenario on its own virtual-time loop in a
  worker thread (a few at once), with its verdict, recording and plot.

    python examples/service/app.py [--port 8000] [--out out/service]

Endpoints::

    GET    /health                liveness (answers while simulations run)
    POST   /runs                  {"scenario": "acceptance" | {...inline...},
                                   "set": ["nav.kp_lin=0.5"], "seed": 3} -> 202 {"id": ...}
    GET    /runs                  every run and its status
    GET    /runs/{id}?wait=10     status, sim time so far, verdict (wait: for the end, s)
    GET    /runs/{id}/recording   the finished run's MCAP file (409 while it runs)
    GET    /runs/{id}/plot        the finished run's trajectory.png (409 while it runs)
    DELETE /runs/{id}             cancel; its recording is finished and indexed
    GET    /live/pose?hz=10       text/event-stream of {"t", "x", "y", "yaw"} (odometry)
    POST   /live/goal             {"x": 4.0, "y": 1.5} -> 202
    GET    /live/graph            actors, topics, QoS and statistics of the live stack

Bad input gets a 4xx whose ``error`` is one line naming the request's field (``scenario``,
``set``, ``seed``, ``goal``), what is wrong and what is valid. The live robot's recording,
OUT/live.mcap, rotates at ``--live-record-mb`` (64 MB): the finished file becomes
live.1.mcap (older ones move up; ``--live-record-keep`` of them stay, default 2), so disk
use stays under about (keep + 1) x the cap. The server binds to 127.0.0.1 unless told
otherwise.

Bounds (issue 27 item 7; ADR 0050): at most ``--max-runs`` simulations run at once and
``--max-queued`` more wait for a slot; past that, POST /runs is answered 503 with a
``Retry-After`` (s) instead of queueing without limit. A finished run is forgotten (404,
its files stay in OUT/runs/ID) ``--keep-finished-s`` seconds after it ended, or sooner
when more than ``--keep-finished`` finished runs are known (oldest first).

What a client may ask is narrower than the CLI (issues 17, 41; ADR 0076): ``set`` takes
only the keys of :data:`CLIENT_KEYS` (tuning numbers, flags, choices), scenes and
scenarios are built-in ones, so the server reads no file, imports no code and opens no
hardware a client names, and its errors never say whether a path exists; bodies of at
most 1 MiB of UTF-8 JSON, headers within ``--header-timeout`` s, a body within
``--body-timeout`` s, at most ``--max-connections`` open. Ctrl-C or SIGTERM cancels every
run at once (each finishes its recording), ends the pose streams, then closes the live
robot and its recording; a second signal is ignored until that is done.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import fnmatch
import json
import logging
import math
import signal
import socket
import sys
import threading
import time
import uuid
from collections.abc import AsyncIterator, Awaitable, Callable, Iterator
from contextlib import AsyncExitStack, asynccontextmanager
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType
from typing import Any

import anyio
import anyio.to_thread
import uvicorn
from pydantic import BaseModel, ConfigDict, Field, ValidationError
from starlette.applications import Starlette
from starlette.requests import ClientDisconnect, Request
from starlette.responses import FileResponse, JSONResponse, Response, StreamingResponse
from starlette.routing import Route
from uvicorn.protocols.http.h11_impl import H11Protocol

from otonav.actors import topics
from otonav.cli import load_stack
from otonav.embed import LiveStack, check_run, open_live_stack, run_scenario_async
from otonav.hal.mujoco import SceneError, scene_names
from otonav.limits import check_scale
from otonav.msgs import Odometry
from otonav.record import RotatingRecordingWriter
from otonav.runtime import QoS, RealTime, Reliability
from otonav.scenario import BUILTIN, Coordinate, GoalSpec, ScenarioConfig, Verdict, check_goal
from otonav.stack import (
    ConfigFileError,
    StackConfig,
    apply_overrides,
    describe_validation_error,
    to_json,
)

log = logging.getLogger("otonav.service")

#: Latest pose only: a slow client skips poses, it never holds the robot back.
POSE_QOS = QoS(Reliability.BEST_EFFORT, depth=1)
MAX_WAIT_S = 60.0
MAX_BODY_BYTES = 1 << 20
"""A request body: a run request is a few hundred bytes, an inline scenario a few kB."""
SHOWN_CHARS = 200
"""How much of a client's string an error quotes (a path fits; 10 MB does not)."""
MAX_QUEUED = 64
"""Runs that may wait for a simulation slot (``--max-queued``): beyond, 503."""
KEEP_FINISHED = 256
"""Finished runs the service remembers (``--keep-finished``); the oldest go first."""
KEEP_FINISHED_S = 3600.0
"""Seconds a finished run is remembered (``--keep-finished-s``); its files stay."""
HEADER_TIMEOUT_S = 10.0
"""A connection's request line and headers must have come within this many seconds of
its opening (or of its previous response): ``--header-timeout``."""
BODY_TIMEOUT_S = 30.0
"""A request's body must have come within this many seconds: ``--body-timeout``."""
MAX_CONNECTIONS = 100
"""Connections open at once (``--max-connections``; each pose stream holds one)."""


def _short(value: str) -> str:
    """``repr(value)``, cut to :data:`SHOWN_CHARS` (a 10 MB name stays a short error)."""
    text = repr(value)
    return text if len(text) <= SHOWN_CHARS else f"{text[: SHOWN_CHARS - 3]}..."


class BadRequest(Exception):
    """A 4xx with a one-line message. The connection is closed after a 408 or 413: the
    rest of that body is not waited for."""

    def __init__(self, message: str, status: int = 400, retry_after: int | None = None) -> None:
        super().__init__(message)
        self.status = status
        self.retry_after = retry_after


# -- requests ----------------------------------------------------------------------------


# Strict: JSON's types as they are. `"seed": true` is not seed 1 and `"x": "1"` is not
# x 1.0 (lax pydantic took both; issue 27). An int is still a valid float.
class RunRequest(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)
    scenario: str | dict[str, Any] = "acceptance"
    """A built-in scenario name, or a scenario inline (the keys of a scenario YAML)."""
    set: list[str] = Field(default_factory=list)
    """Stack config overrides, as ``--set`` takes them: ``nav.kp_lin=0.5``."""
    seed: int | None = None


class GoalRequest(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, strict=True)
    x: Coordinate  # bounded as in a scenario file
    y: Coordinate


def _parse(model: type[BaseModel], body: object, source: str) -> Any:
    try:
        return model.model_validate(body)
    except ValidationError as exc:
        raise BadRequest(describe_validation_error(source, exc)) from None


async def _json_body(request: Request, within: float) -> object:
    raw = bytearray()
    with anyio.move_on_after(within) as waited:  # a body trickled byte by byte ends
        async for chunk in request.stream():  # bounded: never holds more than the cap
            raw += chunk
            if len(raw) > MAX_BODY_BYTES:
                raise BadRequest(f"request body: larger than {MAX_BODY_BYTES // 1024} KiB", 413)
    if waited.cancelled_caught:
        raise BadRequest(f"request body: not received within {within:g} s", 408)
    if not raw.strip():  # not taken as {}: a client that sent nothing meant something
        raise BadRequest("request body: empty; send a JSON object (`{}` for every default)")
    try:
        text = bytes(raw).decode("utf-8")
    except UnicodeDecodeError as exc:
        raise BadRequest(
            f"request body: not UTF-8 (byte 0x{raw[exc.start]:02x} at offset {exc.start})"
        ) from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise BadRequest(f"request body: invalid JSON: {exc}") from None
    except RecursionError:
        raise BadRequest("request body: JSON nested too deeply") from None


def _no_files(what: str, value: str, valid: tuple[str, ...]) -> ConfigFileError:
    """The same answer whatever ``value`` names, existing or not: no oracle."""
    return ConfigFileError(
        f"{what} {_short(value)} is not a built-in scene ({', '.join(valid)}); "
        "the service reads no files"
    )


CLIENT_KEYS = (
    *("nav.*", "guard.*", "safety.*", "base.*", "rates.*"),
    *("world.timestep", "world.lidar_*", "world.odometry_error.*"),
    *("robot.wheel_radius", "robot.wheel_separation", "robot.max_v", "robot.max_omega"),
    *("robot.footprint", "hal.sim.*"),
)
"""What a client's ``set`` may name (fnmatch patterns; ADR 0076): numbers, flags and
choices that tune the stack. Nothing else: no file (``robot.model``, ``world.scene``), no
code (``actors``), no choice of HAL or hardware (``hal.kind``, ``hal.can``; the emulated
drives' ``hal.sim`` faults are tuning), no DDS (``ros2``). An allow-list, so a key
added to the config later is refused until someone decides a client may set it."""


def check_client_keys(assignments: list[str]) -> None:
    """Refuse an assignment whose key :data:`CLIENT_KEYS` does not allow, whatever its
    value: the answer never depends on what the value names."""
    for assignment in assignments:
        key, sep, _value = assignment.partition("=")
        key = key.strip()
        if sep and not any(fnmatch.fnmatchcase(key, allowed) for allowed in CLIENT_KEYS):
            raise BadRequest(
                f"set: {_short(key)} is not a key a client may set (the service reads no "
                f"files a client names, imports no code and opens no hardware); a client "
                f"may set {', '.join(CLIENT_KEYS)}"
            )


def resolve_scenario(spec: str | dict[str, Any], seed: int | None) -> tuple[ScenarioConfig, str]:
    """The scenario and the name errors use for it (as ``otonav run --scenario`` does).
    The service runs built-in or inline scenarios in built-in scenes: it reads no file a
    client names (a scenario YAML, an MJCF scene)."""
    if isinstance(spec, dict):
        source = "scenario"
        try:
            # JSON mode, as for files: strict numbers, lists fit the tuple fields.
            scenario = ScenarioConfig.model_validate_json(to_json(spec, source))
        except ValidationError as exc:
            raise ConfigFileError(describe_validation_error(source, exc)) from None
        if scenario.scene is not None and scenario.scene not in scene_names():
            raise _no_files(f"{source}: scene", scenario.scene, scene_names())
    elif spec in BUILTIN:
        scenario, source = BUILTIN[spec], f"scenario '{spec}'"
    else:  # never looked up on disk: the answer must not depend on what exists there
        raise ConfigFileError(
            f"scenario: {_short(spec)} is not a built-in scenario ({', '.join(BUILTIN)}); "
            "give one of those names or a scenario object (the service reads no files)"
        )
    if seed is not None:
        data = scenario.model_dump()
        data["seed"] = seed
        try:
            scenario = ScenarioConfig.model_validate(data)
        except ValidationError as exc:  # the location says "seed": no prefix to repeat it
            raise ConfigFileError(describe_validation_error("", exc).removeprefix(": ")) from None
    return scenario, source


# -- runs --------------------------------------------------------------------------------


@dataclass(slots=True)
class Run:
    id: str
    scenario: str
    out_dir: Path
    status: str = "queued"  # queued | running | passed | failed | cancelled | error
    verdict: Verdict | None = None
    error: str | None = None
    sim_loop: asyncio.AbstractEventLoop | None = None  # while it runs (its world hangs on it)
    sim_time: float | None = None  # where it ended
    task: asyncio.Task[None] | None = None
    done: asyncio.Event = field(default_factory=asyncio.Event)
    finished_at: float | None = None  # Runs.clock() when it ended

    def as_dict(self) -> dict[str, Any]:
        recording = self.out_dir / "recording.mcap"
        sim_time = self.sim_time
        if self.sim_loop is not None:
            sim_time = self.sim_loop.time()  # the run's loop time is its sim time
        return {
            "id": self.id,
            "scenario": self.scenario,
            "status": self.status,
            "sim_time_s": sim_time,
            "verdict": self.verdict.as_dict() if self.verdict else None,
            "error": self.error,
            "recording": str(recording) if recording.exists() else None,
            "links": {
                name: f"/runs/{self.id}/{name}"
                for name, path in (("recording", recording), ("plot", self.plot_path))
                if self.done.is_set() and path.exists()
            },
        }

    @property
    def plot_path(self) -> Path:
        return self.out_dir / "trajectory.png"


class Runs:
    """Simulation runs: each an asyncio task awaiting ``run_scenario_async``. At most
    ``max_runs + max_queued`` unfinished ones (:meth:`start` refuses more); finished ones
    are forgotten after ``keep_finished_s`` of ``clock`` or beyond ``keep_finished``."""

    def __init__(
        self,
        out_root: Path,
        max_runs: int,
        *,
        max_queued: int = MAX_QUEUED,
        keep_finished: int = KEEP_FINISHED,
        keep_finished_s: float = KEEP_FINISHED_S,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.out_root = out_root
        self.max_runs = max_runs
        self.max_queued = max_queued
        self.keep_finished = keep_finished
        self.keep_finished_s = keep_finished_s
        self.clock = clock
        self.limiter: anyio.CapacityLimiter | None = None
        self.runs: dict[str, Run] = {}
        self._run_walls: list[float] = []  # wall s of the last runs: Retry-After's estimate

    def forget_finished(self) -> None:
        """Drop finished runs past their time, then the oldest beyond the count (their
        files stay on disk). Called whenever the runs are looked at: no timer needed."""
        now = self.clock()
        done = sorted(
            (r for r in self.runs.values() if r.finished_at is not None),
            key=lambda r: r.finished_at or 0.0,
        )
        expired = [r for r in done if now - (r.finished_at or 0.0) >= self.keep_finished_s]
        kept = [r for r in done if r not in expired]
        for run in expired + kept[: max(0, len(kept) - self.keep_finished)]:
            del self.runs[run.id]

    def unfinished(self) -> int:
        return sum(1 for r in self.runs.values() if not r.done.is_set())

    def retry_after(self) -> int:
        """Seconds until a queue slot is likely free: a run's recent mean wall time times
        the queue's depth per slot (at least 1)."""
        mean = sum(self._run_walls) / len(self._run_walls) if self._run_walls else 1.0
        return max(1, math.ceil(mean * self.unfinished() / self.max_runs))

    def start(self, scenario: ScenarioConfig, stack: StackConfig, source: str) -> Run:
        assert self.limiter is not None, "runs start once the app has started"
        self.forget_finished()
        if self.unfinished() >= self.max_runs + self.max_queued:
            raise BadRequest(
                f"busy: {self.max_runs} runs running and {self.max_queued} waiting "
                "(the most --max-runs and --max-queued allow); retry later",
                503,
                retry_after=self.retry_after(),
            )
        run_id = uuid.uuid4().hex[:12]
        run = Run(run_id, scenario.name, self.out_root / run_id)
        self.runs[run_id] = run
        run.task = asyncio.get_running_loop().create_task(
            self._execute(run, scenario, stack, source), name=f"run:{run_id}"
        )
        run.task.add_done_callback(lambda _task: self._cancelled_unstarted(run))
        return run

    def _cancelled_unstarted(self, run: Run) -> None:
        """A task cancelled before it first ran never enters ``_execute`` (a DELETE
        right after the POST): end the run here, or its waiters would wait forever."""
        if not run.done.is_set():
            run.status, run.finished_at = "cancelled", self.clock()
            run.done.set()

    async def _execute(
        self, run: Run, scenario: ScenarioConfig, stack: StackConfig, source: str
    ) -> None:
        host = asyncio.get_running_loop()

        def started(loop: asyncio.AbstractEventLoop, _task: asyncio.Task[None]) -> None:
            run.sim_loop = loop  # called in the worker thread
            host.call_soon_threadsafe(_mark_running, run)

        try:
            verdict = await run_scenario_async(
                scenario,
                stack,
                out_dir=run.out_dir,
                limiter=self.limiter,
                on_start=started,
                source=source,
            )
        except asyncio.CancelledError:
            run.status = "cancelled"  # this task is the run: its cancellation ends here
        except (ConfigFileError, SceneError) as exc:
            run.status, run.error = "error", str(exc)
        except OSError as exc:  # its directory removed, the disk full: one line, no trace
            run.status, run.error = "error", f"{type(exc).__name__}: {exc}"
            log.warning("run %s: %s", run.id, run.error)
        except Exception as exc:
            log.exception("run %s failed", run.id)
            run.status, run.error = "error", f"{type(exc).__name__}: {exc}"
        else:
            run.verdict = verdict
            run.status = "passed" if verdict.passed else "failed"
            self._run_walls = [*self._run_walls[-15:], verdict.wall_time_s]
        finally:
            if run.sim_loop is not None:
                run.sim_time = run.verdict.sim_time_s if run.verdict else run.sim_loop.time()
                run.sim_loop = None
            run.finished_at = self.clock()
            run.done.set()

    async def cancel(self, run: Run) -> None:
        if run.task is not None and not run.task.done():
            run.task.cancel()
        await run.done.wait()

    def cancel_all(self) -> None:
        """Cancel every run that has not ended (each then finishes its recording)."""
        for run in self.runs.values():
            if run.task is not None and not run.task.done():
                run.task.cancel()

    async def shutdown(self) -> None:
        self.cancel_all()
        for run in self.runs.values():
            await run.done.wait()


def _mark_running(run: Run) -> None:
    if run.status == "queued":
        run.status = "running"


# -- the app -----------------------------------------------------------------------------


def _finite(value: Any) -> Any:
    """JSON has no inf/nan: None stands for them."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value


def _json(data: Any, status: int = 200) -> JSONResponse:
    return JSONResponse(_finite(data), status_code=status)


Handler = Callable[[Request], Awaitable[Response]]


def _errors_as_4xx(handler: Handler) -> Handler:
    async def wrapped(request: Request) -> Response:
        try:
            return await handler(request)
        except ClientDisconnect:  # gone mid-body: nobody to answer, nothing to log
            return Response(status_code=400)
        except BadRequest as exc:
            response = _json({"error": str(exc)}, exc.status)
            if exc.retry_after is not None:
                response.headers["Retry-After"] = str(exc.retry_after)
            if exc.status in (408, 413):
                response.headers["Connection"] = "close"
            return response
        except (ConfigFileError, SceneError) as exc:
            return _json({"error": str(exc)}, 400)

    return wrapped


class Service:
    def __init__(
        self,
        *,
        out_root: Path,
        stack: StackConfig = StackConfig(),
        live: bool = True,
        live_scale: float = 1.0,
        live_record: Path | None = None,
        live_record_bytes: int = 64 * 2**20,
        live_record_keep: int = 2,
        max_runs: int = 2,
        max_queued: int = MAX_QUEUED,
        keep_finished: int = KEEP_FINISHED,
        keep_finished_s: float = KEEP_FINISHED_S,
        body_timeout: float = BODY_TIMEOUT_S,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.stack = stack
        self.body_timeout = body_timeout
        self.live_enabled = live
        self.live_scale = live_scale
        self.live_record = live_record
        self.live_record_bytes = live_record_bytes
        self.live_record_keep = live_record_keep
        self.runs = Runs(
            out_root,
            max_runs,
            max_queued=max_queued,
            keep_finished=keep_finished,
            keep_finished_s=keep_finished_s,
            clock=clock,
        )
        self.live: LiveStack | None = None
        self.closing: asyncio.Event | None = None
        """Set when the server stops: waits and pose streams end at once."""
        self._loop: asyncio.AbstractEventLoop | None = None

    def begin_shutdown(self) -> None:
        """From a signal handler (any thread): cancel every run and end the waits and
        pose streams now, not after uvicorn's grace period."""
        loop = self._loop
        if loop is not None and not loop.is_closed():
            loop.call_soon_threadsafe(self._shut_down_now)

    def _shut_down_now(self) -> None:
        if self.closing is not None:
            self.closing.set()
        self.runs.cancel_all()

    @asynccontextmanager
    async def lifespan(self, _app: Starlette) -> AsyncIterator[None]:
        self.runs.limiter = anyio.CapacityLimiter(self.runs.max_runs)
        self.closing = asyncio.Event()
        self._loop = asyncio.get_running_loop()
        async with AsyncExitStack() as stack:
            if self.live_enabled:
                # The live robot runs for as long as the service does: its recording
                # rotates at a size cap instead of growing without limit.
                record = (
                    RotatingRecordingWriter(
                        self.live_record,
                        max_bytes=self.live_record_bytes,
                        keep=self.live_record_keep,
                    )
                    if self.live_record is not None
                    else None
                )
                self.live = await stack.enter_async_context(
                    open_live_stack(self.stack, time=RealTime(self.live_scale), record_to=record)
                )
            try:
                yield
            finally:
                await self.runs.shutdown()
                self.live = None

    def app(self) -> Starlette:
        routes = [
            Route("/health", self.health, methods=["GET"]),
            Route("/runs", _errors_as_4xx(self.post_run), methods=["POST"]),
            Route("/runs", self.list_runs, methods=["GET"]),
            Route("/runs/{run_id}", _errors_as_4xx(self.get_run), methods=["GET"]),
            Route("/runs/{run_id}", _errors_as_4xx(self.delete_run), methods=["DELETE"]),
            Route("/runs/{run_id}/recording", _errors_as_4xx(self.get_recording), methods=["GET"]),
            Route("/runs/{run_id}/plot", _errors_as_4xx(self.get_plot), methods=["GET"]),
            Route("/live/pose", _errors_as_4xx(self.live_pose), methods=["GET"]),
            Route("/live/goal", _errors_as_4xx(self.live_goal), methods=["POST"]),
            Route("/live/graph", _errors_as_4xx(self.live_graph), methods=["GET"]),
        ]
        return Starlette(routes=routes, lifespan=self.lifespan)

    # -- handlers

    async def health(self, _request: Request) -> Response:
        live = self.live
        self.runs.forget_finished()
        active = self.runs.unfinished()
        return _json(
            {
                "status": "ok",
                "live": "running" if live is not None and live.running else "stopped",
                "runs_active": active,
            }
        )

    async def post_run(self, request: Request) -> Response:
        body: RunRequest = _parse(
            RunRequest, await _json_body(request, self.body_timeout), "request"
        )
        scenario, source = resolve_scenario(body.scenario, body.seed)
        check_client_keys(body.set)
        stack = apply_overrides(self.stack, body.set, source="set")
        # What the CLI would reject before running (scene, goal): a 400 now, not a
        # failed run later. Building the world takes milliseconds: off the loop.
        try:
            await anyio.to_thread.run_sync(lambda: check_run(scenario, stack, source=source))
        except SceneError as exc:  # names the scene, not where it came from: add that
            raise BadRequest(f"{source}: {exc}") from None
        run = self.runs.start(scenario, stack, source)
        return _json(run.as_dict(), 202)

    async def list_runs(self, _request: Request) -> Response:
        self.runs.forget_finished()
        return _json([r.as_dict() for r in self.runs.runs.values()])

    def _run(self, request: Request) -> Run:
        run_id = request.path_params["run_id"]
        self.runs.forget_finished()
        run = self.runs.runs.get(run_id)
        if run is None:
            raise BadRequest(
                f"no run {_short(run_id)} (finished runs are forgotten after "
                f"{self.runs.keep_finished_s:g} s or beyond {self.runs.keep_finished}; "
                "their files stay under the service's out directory)",
                404,
            )
        return run

    async def get_run(self, request: Request) -> Response:
        run = self._run(request)
        wait = request.query_params.get("wait")
        if wait is not None:
            try:
                seconds = float(wait)
            except ValueError:
                seconds = math.nan
            if not (math.isfinite(seconds) and seconds >= 0):  # -5 was taken as 0
                raise BadRequest(
                    f"wait={_short(wait)}: expected a number of seconds >= 0, e.g. wait=10 "
                    f"(at most {MAX_WAIT_S:g} are waited)"
                )
            with anyio.move_on_after(min(seconds, MAX_WAIT_S)):
                await _either(run.done, self.closing)
        return _json(run.as_dict())

    def _artifact(self, request: Request, path: Path, what: str) -> Path:
        run = self._run(request)
        if not run.done.is_set():
            raise BadRequest(
                f"run {run.id} is {run.status}: its {what} is not finished yet "
                "(ask again when it ends)",
                409,
            )
        if not path.exists():
            raise BadRequest(f"run {run.id} ({run.status}) left no {what}", 404)
        return path

    async def get_recording(self, request: Request) -> Response:
        run = self._run(request)
        path = self._artifact(request, run.out_dir / "recording.mcap", "recording")
        return FileResponse(path, media_type="application/octet-stream", filename=f"{run.id}.mcap")

    async def get_plot(self, request: Request) -> Response:
        run = self._run(request)
        path = self._artifact(request, run.plot_path, "plot")
        return FileResponse(path, media_type="image/png")

    async def delete_run(self, request: Request) -> Response:
        run = self._run(request)
        await self.runs.cancel(run)
        return _json(run.as_dict())

    def _live(self) -> LiveStack:
        live = self.live
        if live is None or not live.running:
            reason = f": {live.failure}" if live is not None and live.failure else ""
            raise BadRequest(f"the live robot is not running{reason}", 503)
        return live

    async def live_pose(self, request: Request) -> Response:
        live = self._live()
        raw = request.query_params.get("hz", "10")
        try:
            hz = float(raw)
        except ValueError:
            hz = math.nan
        if not 0 < hz <= 100:
            raise BadRequest(f"hz={_short(raw)}: expected a rate in (0, 100]")
        return StreamingResponse(
            _poses(live, 1.0 / hz, self.closing),
            media_type="text/event-stream",
            headers={"Cache-Control": "no-cache"},
        )

    async def live_goal(self, request: Request) -> Response:
        live = self._live()
        goal: GoalRequest = _parse(
            GoalRequest, await _json_body(request, self.body_timeout), "goal"
        )
        try:
            check_goal(
                ScenarioConfig(scene=self.stack.world.scene, goal=GoalSpec(x=goal.x, y=goal.y)),
                self.stack.world.scene,
                live.hal.obstacles(),
                live.hal.walls(),
                source="goal",
            )
        except ConfigFileError as exc:  # "goal: goal: (x, y) is ...": say it once
            raise BadRequest(str(exc).replace("goal: goal: ", "goal ", 1)) from None
        await live.publish_goal(goal.x, goal.y)
        return _json({"goal": {"x": goal.x, "y": goal.y}, "sim_time_s": live.now()}, 202)

    async def live_graph(self, _request: Request) -> Response:
        live = self._live()
        graph = live.graph()
        return _json(
            {
                "sim_time_s": live.now(),
                "slip_s": live.slip_s,
                "actors": [
                    {"name": a.name, "kind": a.kind, "status": a.status, "restarts": a.restarts}
                    for a in graph.actors
                ],
                "topics": [
                    {
                        "name": t.name,
                        "type": t.type,
                        "ros_type": t.ros_type,
                        "publishers": [
                            {"actor": p.actor, "qos": p.qos, "published": p.published}
                            for p in t.publishers
                        ],
                        "subscriptions": [
                            {"actor": s.actor, "qos": s.qos, **s.statistics._asdict()}
                            for s in t.subscriptions
                        ],
                    }
                    for t in graph.topics
                ],
            }
        )


async def _either(first: asyncio.Event, second: asyncio.Event | None) -> None:
    """Until either event is set."""
    if second is None:
        await first.wait()
        return
    waits = [asyncio.ensure_future(first.wait()), asyncio.ensure_future(second.wait())]
    try:
        await asyncio.wait(waits, return_when=asyncio.FIRST_COMPLETED)
    finally:
        for wait in waits:
            wait.cancel()


async def _poses(
    live: LiveStack, period: float, closing: asyncio.Event | None = None
) -> AsyncIterator[str]:
    """Odometry as SSE events, at most one per ``period`` s of sim time. Ends when the
    client goes away (the stream is cancelled), the server stops (``closing``; poses
    come at the odometry rate, so within 10 ms) or the live stack closes."""
    last = -math.inf
    async with live.subscribe(topics.ODOM, Odometry, POSE_QOS) as odom:
        async for message in odom:
            if closing is not None and closing.is_set():
                return
            t = message.header.stamp.to_seconds()
            if t - last < period - 1e-9:
                continue
            last = t
            pose = message.pose.pose
            data = {"t": t, "x": pose.position.x, "y": pose.position.y}
            data["yaw"] = pose.orientation.yaw()
            yield f"event: pose\ndata: {json.dumps(data)}\n\n"


class _GuardedH11(H11Protocol):
    """uvicorn's HTTP/1.1 connection with what it lacks against slow clients (issue 41,
    ADR 0076). A connection that is not being served (no request yet, or its previous
    response sent) is closed ``header_timeout`` s after it opened or after that
    response, however it trickles. At most ``max_connections`` are open: one more
    closes, to make room, the connection that has waited longest without sending a
    whole request (no headers yet, or a body still coming); if every connection is
    being served, the newcomer gets a 503. Subclassed per server by :func:`guarded`."""

    header_timeout = HEADER_TIMEOUT_S
    max_connections = MAX_CONNECTIONS
    opened: dict[_GuardedH11, float]
    """Open connections and when each started waiting (shared by one server's)."""

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        super().connection_made(transport)  # type: ignore[arg-type]
        self._deadline: asyncio.TimerHandle | None = None
        if len(self.opened) >= self.max_connections:
            waiting = [c for c in self.opened if c.unserved(partly=True)]
            if not waiting:
                self.transport.write(_BUSY)
                self.transport.close()
                return
            oldest = min(waiting, key=self.opened.__getitem__)
            del self.opened[oldest]
            oldest.transport.abort()
        self._wait_for_request()

    def connection_lost(self, exc: Exception | None) -> None:
        self.opened.pop(self, None)
        if self._deadline is not None:
            self._deadline.cancel()
        super().connection_lost(exc)

    def on_response_complete(self) -> None:
        super().on_response_complete()
        if not self.transport.is_closing():
            self._wait_for_request()

    def unserved(self, *, partly: bool = False) -> bool:
        """No request in progress (``partly``: or one whose body is still coming)."""
        cycle = self.cycle
        return cycle is None or cycle.response_complete or (partly and cycle.more_body)

    def _wait_for_request(self) -> None:
        if self._deadline is not None:
            self._deadline.cancel()
        self.opened[self] = self.loop.time()
        self._deadline = self.loop.call_later(self.header_timeout, self._expire)

    def _expire(self) -> None:
        self._deadline = None
        if self.unserved():
            self.transport.abort()


_BUSY_BODY = b'{"error": "busy: every connection is serving a request; retry"}'
_BUSY = (
    b"HTTP/1.1 503 Service Unavailable\r\ncontent-type: application/json\r\n"
    b"retry-after: 1\r\nconnection: close\r\n"
    b"content-length: %d\r\n\r\n%s" % (len(_BUSY_BODY), _BUSY_BODY)
)


def guarded(header_timeout: float, max_connections: int) -> type[H11Protocol]:
    """A :class:`_GuardedH11` for one server (its own count of open connections)."""
    return type(
        "GuardedH11",
        (_GuardedH11,),
        {"header_timeout": header_timeout, "max_connections": max_connections, "opened": {}},
    )


class _Server(uvicorn.Server):
    """uvicorn, with the service's shutdown. The first SIGINT/SIGTERM starts it at once:
    every run is cancelled (each finishes its recording), waits and pose streams end,
    then the app's lifespan closes the live robot and its recording. uvicorn's own
    second Ctrl-C would skip that lifespan shutdown (an unindexed live.mcap): here a
    second signal is only acknowledged. The signal is not re-raised: :func:`main`
    returns 130 or 143."""

    def __init__(self, config: uvicorn.Config, service: Service) -> None:
        super().__init__(config)
        self.service = service
        self.first_signal: int | None = None
        self._noted = False

    def handle_exit(self, sig: int, frame: FrameType | None) -> None:
        if self.should_exit:
            if not self._noted:
                self._noted = True
                print(
                    "otonav service: still finishing the runs' and the live recordings",
                    file=sys.stderr,
                    flush=True,
                )
            return
        self.first_signal = sig
        self.should_exit = True
        self.service.begin_shutdown()

    @contextlib.contextmanager
    def capture_signals(self) -> Iterator[None]:
        if threading.current_thread() is not threading.main_thread():
            yield
            return
        handled = (signal.SIGINT, signal.SIGTERM)
        original = {sig: signal.signal(sig, self.handle_exit) for sig in handled}
        try:
            yield
        finally:
            for sig, handler in original.items():
                signal.signal(sig, handler)


RESERVED_DESCRIPTORS = 64
"""Descriptors the service keeps for itself (its recordings, MuJoCo, the loop)."""


def _descriptor_limit() -> int:
    """This process's open-file limit (``ulimit -n``); very large where unknown."""
    try:
        import resource
    except ImportError:  # not on Windows
        return 1 << 30
    soft = resource.getrlimit(resource.RLIMIT_NOFILE)[0]
    return 1 << 30 if soft == resource.RLIM_INFINITY else soft


def create_app(**options: Any) -> Starlette:
    """The app; ``options`` are :class:`Service`'s (``out_root`` is required)."""
    return Service(**options).app()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="otonav-service", description=__doc__.split("\n")[0])
    parser.add_argument("--host", default="127.0.0.1", help="bind address (default loopback)")
    parser.add_argument("--port", type=int, default=8000, help="0: any free port")
    parser.add_argument("--out", type=Path, default=Path("out/service"), help="artifacts")
    parser.add_argument("--config", type=Path, help="stack config YAML (live robot and runs)")
    parser.add_argument("--set", dest="overrides", action="append", default=[])
    parser.add_argument("--no-live", action="store_true", help="no live robot")
    parser.add_argument("--live-scale", type=float, default=1.0, help="sim s per wall s")
    parser.add_argument("--no-live-record", action="store_true")
    parser.add_argument(
        "--live-record-mb",
        type=float,
        default=64.0,
        help="rotate OUT/live.mcap at this size (MB; default 64)",
    )
    parser.add_argument(
        "--live-record-keep",
        type=int,
        default=2,
        help="finished live recordings kept as live.1.mcap, live.2.mcap, ... (default 2)",
    )
    parser.add_argument("--max-runs", type=int, default=2, help="simulations at once")
    parser.add_argument(
        "--max-queued",
        type=int,
        default=MAX_QUEUED,
        help=f"runs waiting for a slot; beyond, POST /runs gets 503 (default {MAX_QUEUED})",
    )
    parser.add_argument(
        "--keep-finished",
        type=int,
        default=KEEP_FINISHED,
        help=f"finished runs remembered, oldest forgotten first (default {KEEP_FINISHED})",
    )
    parser.add_argument(
        "--keep-finished-s",
        type=float,
        default=KEEP_FINISHED_S,
        help=f"seconds a finished run is remembered (default {KEEP_FINISHED_S:g})",
    )
    parser.add_argument(
        "--header-timeout",
        type=float,
        default=HEADER_TIMEOUT_S,
        help=f"s a connection may take to send its headers (default {HEADER_TIMEOUT_S:g})",
    )
    parser.add_argument(
        "--body-timeout",
        type=float,
        default=BODY_TIMEOUT_S,
        help=f"s a request may take to send its body; 408 beyond (default {BODY_TIMEOUT_S:g})",
    )
    parser.add_argument(
        "--max-connections",
        type=int,
        default=MAX_CONNECTIONS,
        help=f"connections open at once (default {MAX_CONNECTIONS})",
    )
    args = parser.parse_args(argv)
    try:
        stack = load_stack(args.config, args.overrides)
        problem = check_scale(args.live_scale, "--live-scale")
        if problem is not None:
            raise ConfigFileError(problem)
        if not 1 <= args.max_runs <= 64:
            raise ConfigFileError(f"--max-runs {args.max_runs}: must be in [1, 64]")
        if not 0 <= args.max_queued <= 100_000:
            raise ConfigFileError(f"--max-queued {args.max_queued}: must be in [0, 100000]")
        if not 0 <= args.keep_finished <= 1_000_000:
            raise ConfigFileError(f"--keep-finished {args.keep_finished}: must be in [0, 1e6]")
        if not (math.isfinite(args.keep_finished_s) and args.keep_finished_s >= 0):
            raise ConfigFileError(f"--keep-finished-s {args.keep_finished_s:g}: must be >= 0")
        if not args.live_record_mb >= 0.1:
            raise ConfigFileError(f"--live-record-mb {args.live_record_mb:g}: must be >= 0.1")
        if args.live_record_keep < 0:
            raise ConfigFileError(f"--live-record-keep {args.live_record_keep}: must be >= 0")
        for flag, seconds in (
            ("--header-timeout", args.header_timeout),
            ("--body-timeout", args.body_timeout),
        ):
            if not 0.1 <= seconds <= 3600:
                raise ConfigFileError(f"{flag} {seconds:g}: must be in [0.1, 3600] s")
        if not 1 <= args.max_connections <= 100_000:
            raise ConfigFileError(
                f"--max-connections {args.max_connections}: must be in [1, 100000]"
            )
        descriptors = _descriptor_limit()
        if args.max_connections > descriptors - RESERVED_DESCRIPTORS:
            # Past it, accept() fails and asyncio logs a traceback per attempt (issue 41).
            raise ConfigFileError(
                f"--max-connections {args.max_connections}: more than this process's "
                f"descriptor limit allows (ulimit -n {descriptors}, less "
                f"{RESERVED_DESCRIPTORS} the service keeps for its own files)"
            )
    except ConfigFileError as exc:
        print(f"otonav: error: {exc}", file=sys.stderr)
        return 2
    out: Path = args.out
    service = Service(
        out_root=out / "runs",
        stack=stack,
        live=not args.no_live,
        live_scale=args.live_scale,
        live_record=None if args.no_live_record else out / "live.mcap",
        live_record_bytes=round(args.live_record_mb * 2**20),
        live_record_keep=args.live_record_keep,
        max_runs=args.max_runs,
        max_queued=args.max_queued,
        keep_finished=args.keep_finished,
        keep_finished_s=args.keep_finished_s,
        body_timeout=args.body_timeout,
    )
    # Bind first, so the address is known (port 0) before the server starts accepting.
    # proto=IPPROTO_TCP matters: asyncio sets TCP_NODELAY only on sockets that say they
    # are TCP; without it Nagle + delayed ACKs add ~40 ms to every response.
    family = socket.AF_INET6 if ":" in args.host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM, socket.IPPROTO_TCP)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    sock.bind((args.host, args.port))
    sock.listen(128)
    host, port = sock.getsockname()[:2]
    print(f"otonav service listening on http://{host}:{port}", flush=True)
    config = uvicorn.Config(
        service.app(),
        http=guarded(args.header_timeout, args.max_connections),
        ws="none",
        log_level="warning",
        lifespan="on",
        timeout_graceful_shutdown=2,
    )
    server = _Server(config, service)
    server.run(sockets=[sock])
    if server.first_signal is not None:
        print(
            "otonav service: stopped; every run was cancelled and the recordings finished",
            file=sys.stderr,
        )
        return 128 + server.first_signal
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
