"""Runtime micro-benchmarks: typed mailbox vs raw anyio stream, timer wakes, fan-out.

Prints medians of several repetitions (wall time via ``time.perf_counter_ns``) and the
ratios the runtime aims for:

- mailbox / raw anyio memory stream, same producer/consumer shape: aim <= 2x;
- virtual-time timer wake / stock-loop wake of an already-due timer: aim <= 1.5x.

Each repetition runs on a fresh loop; one warm-up repetition per case is discarded.

    python benchmarks/runtime_bench.py [--quick] [--reps R] [--json PATH]
"""

from __future__ import annotations

import argparse
import asyncio
import gc
import json
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable, Coroutine
from dataclasses import dataclass
from importlib.metadata import version
from pathlib import Path
from typing import Any

import anyio

from otonav.runtime import Bus, JumpSource, QoS, Reliability, VirtualTimeLoop, virtual_loop_factory
from otonav.runtime._mailbox import Endpoint

DEPTH = 64
TICK = 0.001
MAILBOX_AIM = 2.0
WAKE_AIM = 1.5

LoopFactory = Callable[[], asyncio.AbstractEventLoop]
Bench = Callable[[], Coroutine[Any, Any, int]]  # returns elapsed wall ns


@dataclass(frozen=True, slots=True)
class Sample:
    """A small frozen message."""

    seq: int
    value: float


@dataclass(frozen=True, slots=True)
class Figure:
    key: str
    label: str
    unit: str
    per: int  # operations per repetition
    samples_us: tuple[float, ...]  # µs per operation, one per repetition

    @property
    def median(self) -> float:
        return statistics.median(self.samples_us)


def stock_loop() -> asyncio.AbstractEventLoop:
    return asyncio.SelectorEventLoop()


def virtual_loop() -> asyncio.AbstractEventLoop:
    return virtual_loop_factory()()


def virtual_tick_loop() -> asyncio.AbstractEventLoop:
    return virtual_loop_factory(JumpSource(tick=TICK))()


LOOPS: dict[str, LoopFactory] = {"stock": stock_loop, "virtual": virtual_loop}


# -- the cases -----------------------------------------------------------------------------


def mailbox_case(messages: list[Sample], subscribers: int) -> Bench:
    """One publisher, ``subscribers`` reliable mailboxes (depth 64), one consumer task each."""

    async def run() -> int:
        bus = Bus()
        qos = QoS(Reliability.RELIABLE, depth=DEPTH)
        pub = bus.publisher("/bench", Sample, qos, endpoint=Endpoint("producer", "out"))
        subs = [
            bus.subscribe("/bench", Sample, qos, endpoint=Endpoint(f"consumer{i}", "in"))
            for i in range(subscribers)
        ]
        n = len(messages)
        last: list[int] = []

        async def produce() -> None:
            publish = pub.publish
            for message in messages:
                await publish(message)

        async def consume(recv: Callable[[], Coroutine[Any, Any, Sample]]) -> None:
            message = None
            for _ in range(n):
                message = await recv()
            assert message is not None
            last.append(message.seq)

        t0 = time.perf_counter_ns()
        await asyncio.gather(produce(), *(consume(s.recv) for s in subs))
        elapsed = time.perf_counter_ns() - t0
        assert last == [n - 1] * subscribers, last
        return elapsed

    return run


def raw_stream_case(messages: list[Sample]) -> Bench:
    """The same shape through ``anyio.create_memory_object_stream(64)``."""

    async def run() -> int:
        send, receive = anyio.create_memory_object_stream[Sample](DEPTH)
        n = len(messages)
        last: list[int] = []

        async def produce() -> None:
            for message in messages:
                await send.send(message)

        async def consume() -> None:
            message = None
            for _ in range(n):
                message = await receive.receive()
            assert message is not None
            last.append(message.seq)

        t0 = time.perf_counter_ns()
        await asyncio.gather(produce(), consume())
        elapsed = time.perf_counter_ns() - t0
        send.close()
        receive.close()
        assert last == [n - 1], last
        return elapsed

    return run


def virtual_sleep_case(k: int) -> Bench:
    """``k`` sequential ``asyncio.sleep(TICK)``: each makes the virtual loop advance."""

    async def run() -> int:
        loop = asyncio.get_running_loop()
        assert isinstance(loop, VirtualTimeLoop)
        wakes0 = loop.wakes
        t0 = time.perf_counter_ns()
        for _ in range(k):
            await asyncio.sleep(TICK)
        elapsed = time.perf_counter_ns() - t0
        assert loop.wakes - wakes0 == k, (loop.wakes - wakes0, k)
        return elapsed

    return run


def due_timer_case(k: int) -> Bench:
    """``k`` sequential waits on a timer that is already due when scheduled: the loop's
    whole timer path (call_at, heap, select(0), pop, run, wake the task) without waiting.
    Shaped like ``asyncio.sleep`` (future + timer + cancel in ``finally``)."""

    async def run() -> int:
        loop = asyncio.get_running_loop()
        t0 = time.perf_counter_ns()
        for _ in range(k):
            future = loop.create_future()
            handle = loop.call_at(loop.time() - 1.0, future.set_result, None)
            try:
                await future
            finally:
                handle.cancel()
        return time.perf_counter_ns() - t0

    return run


def real_sleep_case(k: int) -> Bench:
    """``k`` sequential real ``asyncio.sleep(TICK)`` on the stock loop (context only)."""

    async def run() -> int:
        t0 = time.perf_counter_ns()
        for _ in range(k):
            await asyncio.sleep(TICK)
        return time.perf_counter_ns() - t0

    return run


# -- running -------------------------------------------------------------------------------


def measure(
    key: str, label: str, unit: str, factory: LoopFactory, bench: Bench, per: int, reps: int
) -> Figure:
    samples: list[float] = []
    for i in range(reps + 1):  # the first repetition is a warm-up
        gc.collect()
        with asyncio.Runner(loop_factory=factory) as runner:
            elapsed_ns = runner.run(bench())
        if i:
            samples.append(elapsed_ns / 1000.0 / per)
    return Figure(key, label, unit, per, tuple(samples))


def ratio(num: Figure, den: Figure, aim: float | None) -> dict[str, Any]:
    value = num.median / den.median
    return {
        "num": num.key,
        "den": den.key,
        "ratio": value,
        "aim": aim,
        "meets_aim": None if aim is None else value <= aim,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--quick", action="store_true", help="tiny sizes: a CI smoke run")
    parser.add_argument("--reps", type=int, default=None, help="repetitions (default 7; 5 quick)")
    parser.add_argument("--json", type=Path, default=None, metavar="PATH", help="write JSON")
    args = parser.parse_args(argv)

    n = 2_000 if args.quick else 100_000
    n_fan = 500 if args.quick else 25_000
    k = 500 if args.quick else 20_000
    k_real = 20 if args.quick else 300
    reps: int = args.reps if args.reps is not None else (5 if args.quick else 7)
    if reps < 1:
        parser.error("--reps must be >= 1")

    messages = [Sample(i, float(i)) for i in range(n)]
    fan_messages = messages[:n_fan]
    figures: dict[str, Figure] = {}
    ratios: dict[str, dict[str, Any]] = {}

    def add(fig: Figure) -> Figure:
        figures[fig.key] = fig
        return fig

    for name, factory in LOOPS.items():
        mb = add(
            measure(
                f"mailbox_{name}",
                f"mailbox 1->1, {name} loop",
                "us/msg",
                factory,
                mailbox_case(messages, 1),
                n,
                reps,
            )
        )
        raw = add(
            measure(
                f"raw_stream_{name}",
                f"anyio memory stream, {name} loop",
                "us/msg",
                factory,
                raw_stream_case(messages),
                n,
                reps,
            )
        )
        ratios[f"mailbox_vs_raw_{name}"] = ratio(mb, raw, MAILBOX_AIM)

    virt = add(
        measure(
            "wake_virtual",
            f"virtual sleep({TICK:g}), JumpSource({TICK:g})",
            "us/wake",
            virtual_tick_loop,
            virtual_sleep_case(k),
            k,
            reps,
        )
    )
    stock_due = add(
        measure(
            "wake_due_stock",
            "stock loop, already-due timer",
            "us/wake",
            stock_loop,
            due_timer_case(k),
            k,
            reps,
        )
    )
    virt_due = add(
        measure(
            "wake_due_virtual",
            "virtual loop, already-due timer",
            "us/wake",
            virtual_tick_loop,
            due_timer_case(k),
            k,
            reps,
        )
    )
    add(
        measure(
            "wake_real_stock",
            f"stock real sleep({TICK:g}) (context)",
            "us/wake",
            stock_loop,
            real_sleep_case(k_real),
            k_real,
            reps,
        )
    )
    ratios["wake_virtual_vs_due_stock"] = ratio(virt, stock_due, WAKE_AIM)
    ratios["due_virtual_vs_due_stock"] = ratio(virt_due, stock_due, None)

    for name, factory in LOOPS.items():
        for subs in (4, 16):
            add(
                measure(
                    f"fanout{subs}_{name}",
                    f"fan-out 1->{subs}, {name} loop",
                    "us/publish",
                    factory,
                    mailbox_case(fan_messages, subs),
                    n_fan,
                    reps,
                )
            )

    print(
        f"otonav runtime bench: python {platform.python_version()}, anyio {version('anyio')}, "
        f"{os.cpu_count()} cpu, {reps} reps (+1 warm-up), N={n}, K={k}, fan-out N={n_fan}"
        f"{' [quick]' if args.quick else ''}"
    )
    width = max(len(f.label) for f in figures.values())
    print(f"{'case':<{width}}  {'median':>9}  {'min':>9}  {'max':>9}  unit")
    for fig in figures.values():
        print(
            f"{fig.label:<{width}}  {fig.median:9.3f}  {min(fig.samples_us):9.3f}  "
            f"{max(fig.samples_us):9.3f}  {fig.unit}"
        )
    print("ratios (of medians):")
    for key, r in ratios.items():
        verdict = (
            ""
            if r["aim"] is None
            else f"  aim <= {r['aim']:g}x: " + ("ok" if r["meets_aim"] else "MISSED")
        )
        print(f"  {key:<28} {r['ratio']:6.2f}x{verdict}")
    print(
        "baseline: the stock loop cannot jump time, so a wake is compared with a timer\n"
        "  scheduled already due (call_at(time() - 1)): the stock loop's full timer path\n"
        "  (heap push, select(0), pop, callback, task wake-up) with no waiting. The\n"
        "  virtual row is a real sleep(0.001) whose deadline the loop advances to;\n"
        "  'virtual loop, already-due timer' isolates the loop's overhead without the jump."
    )

    if args.json is not None:
        payload = {
            "meta": {
                "python": sys.version,
                "anyio": version("anyio"),
                "cpu_count": os.cpu_count(),
                "reps": reps,
                "quick": args.quick,
                "n": n,
                "k": k,
                "k_real": k_real,
                "n_fanout": n_fan,
                "depth": DEPTH,
                "tick": TICK,
            },
            "figures": {
                key: {
                    "label": f.label,
                    "unit": f.unit,
                    "per_rep": f.per,
                    "median": f.median,
                    "min": min(f.samples_us),
                    "max": max(f.samples_us),
                    "samples": list(f.samples_us),
                }
                for key, f in figures.items()
            },
            "ratios": ratios,
        }
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(payload, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
