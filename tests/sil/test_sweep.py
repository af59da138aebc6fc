"""Sweeps on the local process pool: results that do not depend on the worker count, a
repro line that reproduces the run byte for byte, crashed and hung workers recorded as
errors while the sweep goes on, and resuming after SIGTERM or a killed worker with
nothing rerun and nothing lost. The Ray backend is tested last, against a real local
cluster (``ray.init(num_cpus=2)``, about 5 s to start) shared by this module's Ray
tests only."""

from __future__ import annotations

import asyncio
import gc
import hashlib
import json
import os
import shlex
import signal
import subprocess
import sys
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from otonav.cli import main
from otonav.sweep import execute, load_sweep, make_backend, plan_runs, prepare, sweep_results
from otonav.sweep._plan import RunTask
from otonav.sweep._results import read_results
from otonav.sweep._worker import FAULT_ENV

pytestmark = pytest.mark.sil

SHORT = "name: {name}\nscene: empty\ngoal: {{x: 1.0, y: 0.3}}\nsim_budget: {budget}\n"


def write_sweep(root: Path, *, names: tuple[str, ...] = (), extra: str = "") -> Path:
    """A cheap sweep: ``short`` passes (3-4 s of sim), ``stuck`` runs out of its 0.5 s
    budget, x nav.max_v {0.3, 0.5} x seeds {0, 1}: 8 runs, half of them failures."""
    (root / "worlds").mkdir(parents=True, exist_ok=True)
    (root / "worlds" / "short.yaml").write_text(SHORT.format(name="short", budget=4.0))
    (root / "worlds" / "stuck.yaml").write_text(SHORT.format(name="stuck", budget=0.5))
    for name in names:
        (root / "worlds" / f"{name}.yaml").write_text(SHORT.format(name=name, budget=4.0))
    sweep = root / "sweep.yaml"
    sweep.write_text(
        "name: test\nscenarios: ['worlds/*.yaml']\noverrides: {nav.max_v: [0.3, 0.5]}\n"
        f"seeds: [0, 1]\n{extra}"
    )
    return sweep


def tasks_of(sweep: Path) -> list[RunTask]:
    return plan_runs(load_sweep(sweep), base=sweep.parent, where=str(sweep))


def fingerprints(records: list[dict[str, Any]]) -> dict[str, tuple[Any, ...]]:
    """What must not depend on the backend: verdict figures and the recording's hash."""
    keys = ("status", "reason", "time_to_goal_s", "min_clearance_m", "final_distance_m",
            "path_length_m", "sim_time_s", "recording_sha256")  # fmt: skip
    return {r["run_id"]: tuple(r[k] for k in keys) for r in records}


def run_inline(sweep: Path, out: Path) -> list[dict[str, Any]]:
    return execute(prepare(out, tasks_of(sweep)), make_backend("inline"))


def test_two_workers_give_the_serial_results_and_the_report(tmp_path: Path) -> None:
    sweep = write_sweep(tmp_path)
    serial = run_inline(sweep, tmp_path / "serial")
    assert main(["sweep", str(sweep), "--out", str(tmp_path / "pool"), "--workers", "2"]) == 1
    pool = read_results(tmp_path / "pool" / "results.jsonl")
    assert len(serial) == len(pool) == 8
    assert fingerprints(pool) == fingerprints(serial)
    assert Counter(r["status"] for r in pool) == {"passed": 4, "failed": 4}
    assert len({r["recording_sha256"] for r in pool}) == 8  # seed and config are in each
    assert all(r["worker"].split(":")[1] != str(os.getpid()) for r in pool)  # not inline

    summary = json.loads((tmp_path / "pool" / "summary.json").read_text())
    assert summary["pass_rate"]["passed"] == 4
    assert summary["pass_rate"]["runs"] == 8
    assert 0.15 < summary["pass_rate"]["low"] < 0.5 < summary["pass_rate"]["high"] < 0.85
    assert summary["by_family"]["short"]["rate"] == 1.0
    assert summary["by_family"]["stuck"]["rate"] == 0.0
    assert set(summary["by_override"]["nav.max_v"]) == {"0.3", "0.5"}
    [group] = summary["failures"]
    assert group["reason"] == "did not reach the goal within # s"
    assert group["count"] == 4
    report = (tmp_path / "pool" / "report.md").read_text()
    assert "otonav run --scenario" in report
    for png in ("pass_fail.png", "histograms.png"):
        assert (tmp_path / "pool" / png).stat().st_size > 5_000
    # keep: failures (the default): the failures' recordings and plots, nothing else
    for r in pool:
        folder = tmp_path / "pool" / "runs" / r["run_id"]
        assert folder.exists() == (r["status"] == "failed")
        if folder.exists():
            data = (folder / "recording.mcap").read_bytes()
            assert hashlib.sha256(data).hexdigest() == r["recording_sha256"]
            assert (folder / "trajectory.png").stat().st_size > 5_000


def test_the_repro_line_reproduces_the_run_byte_for_byte(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    sweep = write_sweep(tmp_path)
    records = run_inline(sweep, tmp_path / "s")
    failed = next(r for r in records if r["status"] == "failed" and r["seed"] == 1)
    argv = shlex.split(failed["repro"])
    assert argv[:2] == ["otonav", "run"]
    assert "--set" in argv
    assert main([*argv[1:], "--out", str(tmp_path / "repro")]) == 1
    recording = (tmp_path / "repro" / "recording.mcap").read_bytes()
    assert hashlib.sha256(recording).hexdigest() == failed["recording_sha256"]


def test_a_generated_world_is_kept_with_a_repro_that_reproduces_it(tmp_path: Path) -> None:
    sweep = tmp_path / "gen.yaml"
    sweep.write_text(  # small, nearly empty worlds: a few seconds of sim each
        "scenarios:\n  - generate: {count: 1, seed: 7, params: {arena: 5, "
        "obstacle_count: [1, 1], start_goal_distance: [1.0, 1.2]}}\nkeep: all\n"
    )
    [record] = run_inline(sweep, tmp_path / "out")
    assert record["scenario"] == "sparse-7"
    assert record["status"] == "passed", record["reason"]
    assert record["world_reachable"] is True
    assert record["shortest_path_m"] >= 1.0
    argv = shlex.split(record["repro"])
    assert argv[3].endswith("runs/" + record["run_id"] + "/scenario.yaml")
    assert main([*argv[1:], "--out", str(tmp_path / "repro")]) == 0
    recording = (tmp_path / "repro" / "recording.mcap").read_bytes()
    assert hashlib.sha256(recording).hexdigest() == record["recording_sha256"]


def test_a_failed_generated_world_keeps_its_scenario_for_the_repro_even_with_keep_none(
    tmp_path: Path,
) -> None:
    sweep = tmp_path / "gen.yaml"
    sweep.write_text(  # the same small world, a navigator that stops a metre short
        "scenarios:\n  - generate: {count: 1, seed: 7, params: {arena: 5, "
        "obstacle_count: [1, 1], start_goal_distance: [1.0, 1.2]}}\n"
        "overrides: {nav.tolerance: [1.0]}\nkeep: none\n"
    )
    [record] = run_inline(sweep, tmp_path / "out")
    assert record["status"] == "failed", record["reason"]
    folder = tmp_path / "out" / record["artifacts"]
    assert sorted(p.name for p in folder.iterdir()) == ["scenario.yaml"]  # no recording
    argv = shlex.split(record["repro"])
    assert argv[3] == str(folder / "scenario.yaml")
    assert main([*argv[1:], "--out", str(tmp_path / "repro")]) == 1
    recording = (tmp_path / "repro" / "recording.mcap").read_bytes()
    assert hashlib.sha256(recording).hexdigest() == record["recording_sha256"]


def test_a_kept_failures_plot_is_the_one_otonav_run_draws(tmp_path: Path) -> None:
    """Issue 39: a sweep's kept plot is drawn by the run from its ground truth, with the
    title, legend and path label of ``otonav run``'s: the repro's plot, byte for byte
    (it was redrawn from the recording, labelled "path (odometry)")."""
    sweep = tmp_path / "gen.yaml"
    sweep.write_text(
        "scenarios:\n  - generate: {count: 1, seed: 7, params: {arena: 5, "
        "obstacle_count: [1, 1], start_goal_distance: [1.0, 1.2]}}\n"
        "overrides: {nav.tolerance: [1.0]}\nkeep: failures\n"
    )
    [record] = run_inline(sweep, tmp_path / "out")
    assert record["status"] == "failed", record["reason"]
    kept = (tmp_path / "out" / record["artifacts"] / "trajectory.png").read_bytes()
    argv = shlex.split(record["repro"])
    assert main([*argv[1:], "--out", str(tmp_path / "repro")]) == 1
    assert kept == (tmp_path / "repro" / "trajectory.png").read_bytes()


def test_a_warm_worker_frees_each_run_before_the_next(tmp_path: Path) -> None:
    """A run's objects form reference cycles; a warm worker that left them to the cyclic
    collector's own pace had ~10 runs' worlds alive (a 13.6 MB MjData each) and its RSS
    crept (docs/adr/0029). Here the real worker code runs real runs in this process, and
    after each one no object of a per-run type may be alive, without this test
    collecting anything."""
    from otonav.record._writer import RecordingWriter
    from otonav.runtime._loop import VirtualTimeLoop
    from otonav.runtime._system import System
    from otonav.stack._session import StackSession
    from otonav.sweep._worker import WarmWorker

    per_run = (StackSession, System, VirtualTimeLoop, RecordingWriter)

    def alive() -> list[str]:
        return [type(o).__name__ for o in gc.get_objects() if isinstance(o, per_run)]

    sweep = write_sweep(tmp_path)
    tasks = [t for t in tasks_of(sweep) if t.scenario == "short"][:3]  # 3-4 s of sim each
    (tmp_path / "scratch").mkdir()
    gc.collect()
    before = len(alive())  # other tests' live ones, if any (none expected)
    worker = WarmWorker(tmp_path / "scratch")  # freezes what exists: hidden from alive()
    try:
        for task in tasks:
            assert worker.run(task).status == "passed"
            assert alive() == []
    finally:
        gc.unfreeze()  # this process is pytest's, not a worker's
    assert len(alive()) == before  # none hidden by a freeze either


def test_crashed_and_hung_workers_are_errors_then_resume_retries_only_them(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    sweep = write_sweep(tmp_path, names=("crashy", "hangy"), extra="wall_ceiling_s: 8\n")
    sweep.write_text(  # one run per scenario: a hang costs its ceiling in wall time
        sweep.read_text()
        .replace("overrides: {nav.max_v: [0.3, 0.5]}\n", "")
        .replace("seeds: [0, 1]", "seeds: [1]")
    )
    out = tmp_path / "out"
    monkeypatch.setenv(FAULT_ENV, "crash:crashy,hang:hangy")
    assert main(["sweep", str(sweep), "--out", str(out), "--workers", "2"]) == 1
    first = read_results(out / "results.jsonl")
    assert len(first) == 4  # every run has a record: the sweep went on
    status = {r["scenario"]: (r["status"], r["reason"]) for r in first}
    assert status["crashy"][0] == status["hangy"][0] == "error"
    assert "worker died (killed by SIGKILL)" in status["crashy"][1]
    assert "hung: no result after 9 s of wall time" in status["hangy"][1]
    assert status["short"][0] == "passed"
    assert status["stuck"][0] == "failed"
    errors = {r["run_id"] for r in first if r["status"] == "error"}

    monkeypatch.delenv(FAULT_ENV)  # (inline runs in this process: the fault would kill it)
    healthy = [r for r in first if r["status"] != "error"]
    assert fingerprints(healthy) == fingerprints(
        [r for r in run_inline(sweep, tmp_path / "ref") if r["run_id"] not in errors]
    )
    argv = ["sweep", str(sweep), "--out", str(out), "--resume", "--backend", "inline"]
    assert main(argv) == 1  # errors are results: nothing reruns
    assert len(read_results(out / "results.jsonl")) == 4
    assert main([*argv, "--retry-errors"]) == 1  # stuck still fails
    records = read_results(out / "results.jsonl")
    # Exactly the 2 errors ran again, and their new records replaced the old ones: one
    # line per run (issue 27: the file kept both, and jq or pandas saw the run twice).
    assert len(records) == 4
    assert Counter(r["run_id"] for r in records) == Counter({r["run_id"]: 1 for r in first})
    assert {r["run_id"] for r in records[2:]} == errors
    assert all(r["status"] == "passed" for r in records[2:])
    assert records[:2] == healthy
    summary = json.loads((out / "summary.json").read_text())
    assert summary["pass_rate"]["errors"] == 0
    assert summary["finished"] == summary["planned"] == 4


def test_sigterm_stops_the_sweep_and_resume_finishes_it_without_rerunning(
    tmp_path: Path,
) -> None:
    sweep = write_sweep(tmp_path)
    sweep.write_text(sweep.read_text().replace("seeds: [0, 1]", "seeds: {start: 0, count: 3}"))
    out = tmp_path / "out"
    argv = [sys.executable, "-m", "otonav", "sweep", str(sweep), "--out", str(out)]
    with subprocess.Popen(
        [*argv, "--workers", "2"], stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True
    ) as proc:
        assert proc.stderr is not None
        seen = 0
        for line in proc.stderr:  # one line per finished run (not a terminal)
            seen += line.startswith("sweep: [")
            if seen == 3:
                proc.send_signal(signal.SIGTERM)
                break
        rest = proc.stderr.read()
        assert proc.wait(timeout=60) == 143, rest
    assert "finish with --resume" in rest
    assert "Traceback" not in rest
    before = read_results(out / "results.jsonl")
    assert 3 <= len(before) < 12
    summary = json.loads((out / "summary.json").read_text())
    assert summary["complete"] is False
    assert summary["finished"] == len(before)

    # resumed on another backend: a run's result does not depend on where it ran
    assert main(["sweep", str(sweep), "--out", str(out), "--resume", "--backend", "inline"]) == 1
    after = read_results(out / "results.jsonl")
    assert after[: len(before)] == before  # nothing lost, nothing rewritten
    assert Counter(r["run_id"] for r in after) == Counter({t.run_id: 1 for t in tasks_of(sweep)})
    assert fingerprints(after) == fingerprints(run_inline(sweep, tmp_path / "ref"))


def test_the_api_yields_results_as_they_come_and_stops_when_left(tmp_path: Path) -> None:
    sweep = write_sweep(tmp_path)
    tasks = tasks_of(sweep)
    out = tmp_path / "out"

    async def first_two() -> list[dict[str, Any]]:
        got = []
        async for record in sweep_results(tasks, out=out, backend="inline"):
            got.append(record)
            if len(got) == 2:
                break  # leaving the loop stops the sweep
        return got

    got = asyncio.run(first_two())
    on_disk = read_results(out / "results.jsonl")
    assert on_disk[:2] == got
    assert len(on_disk) < len(tasks)
    assert not (out / "summary.json").exists()  # an unfinished sweep has no report yet

    async def the_rest() -> list[dict[str, Any]]:
        return [r async for r in sweep_results(tasks, out=out, backend="inline", resume=True)]

    rest = asyncio.run(the_rest())
    assert len(on_disk) + len(rest) == len(tasks)
    assert {r["run_id"] for r in on_disk} | {r["run_id"] for r in rest} == {t.run_id for t in tasks}
    assert json.loads((out / "summary.json").read_text())["complete"] is True


def test_cancelling_the_iterating_task_stops_the_pool(tmp_path: Path) -> None:
    sweep = write_sweep(tmp_path)
    tasks = tasks_of(sweep)
    out = tmp_path / "out"
    pids: set[str] = set()

    async def scenario() -> None:
        async def consume() -> None:
            async for record in sweep_results(tasks, out=out, workers=2):
                pids.add(record["worker"].rsplit(":", 1)[1])
                first.set()

        first = asyncio.Event()
        task = asyncio.create_task(consume())
        await first.wait()
        task.cancel()
        with pytest.raises(asyncio.CancelledError):
            await task

    asyncio.run(scenario())
    for pid in pids:  # the workers are gone once the cancellation has returned
        with pytest.raises(ProcessLookupError):
            os.kill(int(pid), 0)
    assert len(read_results(out / "results.jsonl")) < len(tasks)


# -- Ray ---------------------------------------------------------------------------------


_RAY_AUTH = ("RAY_AUTH_MODE", "RAY_AUTH_TOKEN", "RAY_AUTH_TOKEN_PATH")


@pytest.fixture(scope="module")
def local_ray(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """The cluster the Ray backend starts on demand (``init_local``), with an empty
    home: yields that home, where Ray must leave nothing (no ``.ray/auth_token``)."""
    import ray  # the dev extra includes otonav[ray]: a missing Ray fails, never skips

    from otonav.sweep.backends._ray import init_local

    home = tmp_path_factory.mktemp("home")
    saved = {k: os.environ.pop(k, None) for k in ("HOME", *_RAY_AUTH)}
    os.environ["HOME"] = str(home)
    try:
        # Workers inherit the environment the cluster starts with: the crash hook is set
        # for them only (this process runs inline references and must not have it).
        os.environ[FAULT_ENV] = "crash:crashy"
        try:
            # results are small: 128 MB of object store (default: 30 % of RAM)
            init_local(2, object_store_memory=128 * 1024 * 1024)
        finally:
            del os.environ[FAULT_ENV]
        yield home
        ray.shutdown()
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def test_ray_gives_the_serial_results_and_survives_a_dead_worker(
    local_ray: Path, tmp_path: Path
) -> None:
    sweep = write_sweep(tmp_path, names=("crashy",))
    sweep.write_text(sweep.read_text().replace("seeds: [0, 1]", "seeds: [1]"))
    serial = run_inline(sweep, tmp_path / "serial")  # crashy passes here: no hook in this process
    records = execute(prepare(tmp_path / "ray", tasks_of(sweep)), make_backend("ray", workers=2))
    assert len(records) == len(serial) == 6
    crashed = {r["run_id"] for r in records if r["scenario"] == "crashy"}
    assert all(
        r["status"] == "error" and "worker died" in r["reason"]
        for r in records
        if r["run_id"] in crashed
    )
    healthy = [r for r in records if r["run_id"] not in crashed]
    assert fingerprints(healthy) == fingerprints([r for r in serial if r["run_id"] not in crashed])
    assert {r["status"] for r in healthy} == {"passed", "failed"}
    assert all(r["worker"].split(":")[1] != str(os.getpid()) for r in healthy)  # on Ray
    kept = [r for r in records if r["status"] == "failed"]
    assert all((tmp_path / "ray" / r["artifacts"] / "recording.mcap").exists() for r in kept)
    assert not (local_ray / ".ray").exists()  # Ray's token stayed out of the home
    # --retry-errors after the killed workers: the retried runs' records replace the
    # errors, one line per run in results.jsonl (it used to keep both).
    out = tmp_path / "ray"
    retried = execute(
        prepare(out, tasks_of(sweep), resume=True, retry_errors=True), make_backend("inline")
    )
    assert {r["run_id"] for r in retried} == crashed
    lines = (out / "results.jsonl").read_text().splitlines()
    assert Counter(json.loads(line)["run_id"] for line in lines) == Counter(
        {t.run_id: 1 for t in tasks_of(sweep)}
    )
    assert {r["status"] for r in read_results(out / "results.jsonl")} == {"passed", "failed"}
