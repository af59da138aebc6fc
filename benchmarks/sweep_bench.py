"""Sweep throughput, per-run overhead, Ray against the process pool, and peak RSS.

    python benchmarks/sweep_bench.py [--runs 200] [--shell-runs 8] [--rss 100 1000]
                                     [--no-ray] [--json PATH] [--rss-only]

Every figure is measured in this invocation, so ratios compare like with like on a
shared, noisy machine (quote ratios and medians, not absolute seconds):

- throughput, in sim-seconds per wall-second, of a ``--runs`` sweep of the acceptance
  scenario (seeds 0..runs-1: the same ~13.4 s of sim each, a different recording each)
  on the process pool with 1 worker and with 2, and on a local 2-CPU Ray cluster (its
  start-up timed apart, as for an existing cluster); wall time from the first task
  handed out to the last record written, pool start-up included;
- a shell loop of ``python -m otonav run --scenario acceptance --seed N`` (one
  interpreter per run), timed on ``--shell-runs`` runs and scaled to ``--runs``; runs
  per minute of each (issue 40: the 2-worker sweep >= 8x the loop);
- overhead per run beyond its simulation: in the worker (world build, session set-up,
  finishing and hashing the recording; p50 of wall_time_s - sim_wall_s), and in total
  with 1 worker ((sweep wall - sum of simulation walls) / runs: adds pool start-up,
  dispatch, the results line, artifacts of failures);
- memory: one sweep of ``max(--rss)`` runs of a short scenario (~3 s of sim) on 2
  workers, in a fresh interpreter; as the Nth record is written, for each N in
  ``--rss``, the RSS and peak RSS of the driver and of the workers (``--rss-only``: just
  this part, a few minutes at 1,000 runs).
"""

from __future__ import annotations

import argparse
import json
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from otonav.sweep import execute, make_backend, plan_runs, prepare
from otonav.sweep._spec import SeedRange, SweepSpec

SHORT = "name: short\nscene: empty\ngoal: {x: 1.0, y: 0.3}\nsim_budget: 4.0\n"


def timed_sweep(runs: int, backend: str, workers: int, out: Path) -> dict[str, Any]:
    spec = SweepSpec(scenarios=("acceptance",), seeds=SeedRange(count=runs))
    tasks = plan_runs(spec)
    engine = make_backend(backend, workers=workers)
    prepared = prepare(out, tasks)
    load = Path("/proc/loadavg").read_text().split()[0]
    cpu_before = _cpu()
    start = time.perf_counter()
    records = execute(prepared, engine)
    wall = time.perf_counter() - start
    cpu = _cpu() - cpu_before
    sim = sum(r["sim_time_s"] for r in records)
    sim_walls = [r["sim_wall_s"] for r in records]
    return {
        "backend": backend,
        "workers": workers,
        "runs": len(records),
        "passed": sum(r["status"] == "passed" for r in records),
        "wall_s": wall,
        "sim_s": sim,
        "throughput": sim / wall,
        "load_at_start": load,
        # driver + reaped workers; Ray's workers are not our children (None)
        "sim_per_cpu_s": sim / cpu if backend == "process" else None,
        "run_wall_p50_s": statistics.median(r["wall_time_s"] for r in records),
        "sim_wall_p50_s": statistics.median(sim_walls),
        "in_worker_overhead_p50_ms": 1e3
        * statistics.median(r["wall_time_s"] - r["sim_wall_s"] for r in records),
        "total_overhead_per_run_ms": 1e3 * (wall * workers - sum(sim_walls)) / len(records),
        "hashes": sorted(r["recording_sha256"] for r in records),
    }


def _cpu() -> float:
    me = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def shell_loop(runs: int, out: Path) -> dict[str, Any]:
    walls = []
    for seed in range(runs):
        start = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "otonav", "run", "--scenario", "acceptance", "--seed",
             str(seed), "--out", str(out / f"shell{seed}")],
            check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        walls.append(time.perf_counter() - start)
    return {"runs": runs, "wall_s": sum(walls), "wall_p50_s": statistics.median(walls)}


def _status_mb(pid: int | str) -> dict[str, float]:
    """VmRSS and VmHWM (the peak since the process's last exec) of a process, in MB."""
    out = {}
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        key, _, value = line.partition(":")
        if key in ("VmRSS", "VmHWM"):
            out[key] = int(value.split()[0]) / 1024
    return out


def _children() -> list[int]:
    """Live child processes of this one (the pool's workers)."""
    me, kids = str(Path("/proc/self").resolve().name), []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if fields[1] == me:
            kids.append(int(stat.parent.name))
    return kids


def rss_child(checkpoints: list[int], workers: int) -> None:
    """In a fresh interpreter: one sweep of ``max(checkpoints)`` short runs on the
    process pool; as the record of run N (a checkpoint) is written, print the driver's and
    every live worker's RSS and peak RSS (VmHWM, /proc: not ``ru_maxrss``, which a
    process inherits from its parent across fork and exec)."""
    samples: list[dict[str, Any]] = []
    seen: dict[int, dict[str, float]] = {}
    done = 0

    def on_record(record: dict[str, Any]) -> None:
        nonlocal done
        done += 1
        if done not in checkpoints:
            return
        workers_now = {}
        for pid in _children():
            try:
                workers_now[pid] = _status_mb(pid)
            except OSError:  # exited between the listing and the read
                continue
        seen.update(workers_now)
        driver = _status_mb("self")
        samples.append(
            {
                "runs": done,
                "driver_mb": driver["VmRSS"],
                "driver_peak_mb": driver["VmHWM"],
                "worker_mb": max(w["VmRSS"] for w in workers_now.values()),
                "worker_peak_mb": max(w["VmHWM"] for w in seen.values()),
                "workers": len(workers_now),
                "distinct_workers": len(seen),
            }
        )

    with tempfile.TemporaryDirectory() as tmp:
        scenario = Path(tmp) / "short.yaml"
        scenario.write_text(SHORT)
        spec = SweepSpec(scenarios=(str(scenario),), seeds=SeedRange(count=max(checkpoints)))
        prepared = prepare(Path(tmp) / "out", plan_runs(spec))
        execute(prepared, make_backend("process", workers=workers), on_record=on_record)
    print(json.dumps(samples))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=200)
    parser.add_argument("--shell-runs", type=int, default=8)
    parser.add_argument("--rss", type=int, nargs="*", default=[100, 1000])
    parser.add_argument("--no-ray", action="store_true")
    parser.add_argument("--json", type=Path)
    parser.add_argument("--rss-only", action="store_true", help="only the RSS figures")
    parser.add_argument("--rss-child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.rss_child:
        rss_child(args.rss, 2)
        return
    if args.rss_only:
        report_rss(args.rss)
        return

    figures: dict[str, Any] = {"runs": args.runs}
    load_before = Path("/proc/loadavg").read_text().split()[:3]
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        results = [
            timed_sweep(args.runs, "process", 1, root / "p1"),
            timed_sweep(args.runs, "process", 2, root / "p2"),
        ]
        if not args.no_ray:
            import ray

            from otonav.sweep.backends._ray import init_local

            start = time.perf_counter()
            init_local(2)  # as `--backend ray` starts one: nothing written to ~/.ray
            figures["ray_start_s"] = time.perf_counter() - start
            try:
                results.append(timed_sweep(args.runs, "ray", 2, root / "ray"))
            finally:
                ray.shutdown()
        shell = shell_loop(args.shell_runs, root)
    sim_per_run = results[0]["sim_s"] / results[0]["runs"]
    shell_throughput = sim_per_run * shell["runs"] / shell["wall_s"]
    same = all(r["hashes"] == results[0]["hashes"] for r in results)

    print(f"{args.runs}-run sweep of the acceptance scenario ({sim_per_run:.2f} s of sim each)")
    print(f"load average before: {' '.join(load_before)} (2 cores, shared machine)")
    header = (
        f"{'configuration':<28} {'wall s':>8} {'runs/min':>9} {'sim-s/wall-s':>13} "
        f"{'run p50 ms':>11} {'sim-s/CPU-s':>12} {'load':>5}"
    )
    print(header)
    print("-" * len(header))
    for r in results:
        name = f"{r['backend']}, {r['workers']} worker{'s' if r['workers'] > 1 else ''}"
        print(
            f"{name:<28} {r['wall_s']:8.1f} {60 * r['runs'] / r['wall_s']:9.0f} "
            f"{r['throughput']:13.1f} "
            f"{1e3 * r['run_wall_p50_s']:11.0f} "
            + (f"{r['sim_per_cpu_s']:12.1f}" if r["sim_per_cpu_s"] else f"{'-':>12}")
            + f" {r['load_at_start']:>5}"
        )
    scaled = shell["wall_s"] * args.runs / shell["runs"]
    print(
        f"{'shell loop (scaled from ' + str(shell['runs']) + ')':<28} {scaled:8.1f} "
        f"{60 * shell['runs'] / shell['wall_s']:9.0f} {shell_throughput:13.1f} "
        f"{1e3 * shell['wall_p50_s']:11.0f}"
    )
    p1, p2 = results[0], results[1]
    print()
    print(
        f"2 workers / 1 worker:            {p2['throughput'] / p1['throughput']:.2f}x  "
        "(target >= 1.7)"
    )
    print(
        f"sweep (2 workers) / shell loop:  {p2['throughput'] / shell_throughput:.2f}x in runs "
        "per minute (target >= 8, issue 40; the same runs: ratio of sim-s/wall-s)"
    )
    print(f"sweep (1 worker) / shell loop:   {p1['throughput'] / shell_throughput:.2f}x")
    efficiency = p2["sim_per_cpu_s"] / p1["sim_per_cpu_s"]
    print(
        f"CPU efficiency, 2 workers / 1:   {efficiency:.2f}  (sim-s per CPU-s; with two idle "
        f"cores the 2-worker speed-up would be about {2 * efficiency:.2f}x)"
    )
    if len(results) > 2:
        ray_r = results[2]
        print(
            f"ray 2 CPUs / process 2 workers:  {ray_r['throughput'] / p2['throughput']:.2f}x  "
            f"(target >= 0.75; cluster start-up {figures['ray_start_s']:.1f} s, not counted)"
        )
    print(
        f"overhead per run, in the worker: {p1['in_worker_overhead_p50_ms']:.1f} ms p50 "
        f"(1 worker); total with 1 worker: {p1['total_overhead_per_run_ms']:.1f} ms "
        f"(target <= 20)"
    )
    print(f"recordings identical across configurations: {same}")
    figures["configurations"] = [{k: v for k, v in r.items() if k != "hashes"} for r in results]
    figures["shell"] = {**shell, "throughput": shell_throughput, "scaled_wall_s": scaled}
    figures["identical_recordings"] = same

    figures["rss"] = report_rss(args.rss) if args.rss else []
    print(f"load average after: {' '.join(Path('/proc/loadavg').read_text().split()[:3])}")
    if args.json:
        args.json.write_text(json.dumps(figures, indent=2) + "\n")


def report_rss(checkpoints: list[int]) -> list[dict[str, Any]]:
    child = subprocess.run(
        [sys.executable, __file__, "--rss-child", "--rss", *map(str, checkpoints)],
        check=True, capture_output=True, text=True,
    )  # fmt: skip
    samples: list[dict[str, Any]] = json.loads(child.stdout.strip().splitlines()[-1])
    print(f"RSS during one {max(checkpoints)}-run sweep of a short scenario (2 workers), MB:")
    for r in samples:
        print(
            f"  after {r['runs']:>5} runs: driver {r['driver_mb']:.0f} (peak "
            f"{r['driver_peak_mb']:.0f}), largest worker {r['worker_mb']:.0f} (peak of any "
            f"worker so far {r['worker_peak_mb']:.0f}; {r['distinct_workers']} workers so far)"
        )
    return samples


if __name__ == "__main__":
    main()
