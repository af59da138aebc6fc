"""What building and decoding a message costs (ADR 0086): pydantic's public ways against
the slot-descriptor writes otonav used before, in one interleaved run.

    python benchmarks/message_bench.py [--rounds 15] [--baseline DIR]

Part one, in this process, round by round in turn (medians, us per message):

- ``slots``: ``object.__new__`` and BaseModel's four slot descriptors set by hand (how
  ``Message.fast`` and the CDR decoder built messages before ADR 0086; kept here only
  as the reference);
- ``setstate``: ``object.__new__`` and ``BaseModel.__setstate__`` (the pickle protocol);
- ``construct``: ``model_construct(_fields_set=..., **fields)``;
- ``validated``: ``Model(**fields)``.

for a Vector3 (one object) and an Odometry (eleven nested objects).

Part two: ``decode`` (``otonav.record.cdr``) of an Odometry, a 360-beam LaserScan and a
TFMessage of two transforms, and ``Message.fast`` of a Twist, in this checkout and, with
``--baseline DIR`` (a directory holding another version's ``otonav`` package, e.g.
``git archive aff52d1 otonav | tar -x -C DIR``), in that one, each in its own process,
the two alternating round by round; the ratio is this / baseline.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from typing import Any

N = 20_000


def _per_call(fn: Callable[[], object], n: int = N) -> float:
    start = time.perf_counter()
    for _ in range(n):
        fn()
    return (time.perf_counter() - start) / n * 1e6


def construction() -> dict[str, Callable[[], object]]:
    from pydantic import BaseModel

    from otonav.msgs import (
        Header,
        Odometry,
        Point,
        Pose,
        PoseWithCovariance,
        Quaternion,
        Time,
        Twist,
        TwistWithCovariance,
        Vector3,
    )

    new = object.__new__
    sd = BaseModel.__dict__["__dict__"].__set__
    sf = BaseModel.__dict__["__pydantic_fields_set__"].__set__
    se = BaseModel.__dict__["__pydantic_extra__"].__set__
    sp = BaseModel.__dict__["__pydantic_private__"].__set__
    setstate = BaseModel.__setstate__

    def slots(cls: Any, fields: dict[str, Any]) -> Any:
        m = new(cls)
        sd(m, fields)
        sf(m, cls._otonav_fields)
        se(m, None)
        sp(m, None)
        return m

    def state(cls: Any, fields: dict[str, Any]) -> Any:
        m = new(cls)
        setstate(
            m,
            {
                "__dict__": fields,
                "__pydantic_fields_set__": cls._otonav_fields,
                "__pydantic_extra__": None,
                "__pydantic_private__": None,
            },
        )
        return m

    def construct(cls: Any, fields: dict[str, Any]) -> Any:
        return cls.model_construct(cls._otonav_fields, **fields)

    def validated(cls: Any, fields: dict[str, Any]) -> Any:
        return cls(**fields)

    def odometry(make: Callable[[Any, dict[str, Any]], Any]) -> Any:
        cov = (0.0,) * 36
        header = make(Header, {"stamp": make(Time, {"sec": 1, "nanosec": 2}), "frame_id": "odom"})
        pose = make(
            Pose,
            {
                "position": make(Point, {"x": 1.0, "y": 2.0, "z": 0.0}),
                "orientation": make(Quaternion, {"x": 0.0, "y": 0.0, "z": 0.1, "w": 0.99}),
            },
        )
        twist = make(
            Twist,
            {
                "linear": make(Vector3, {"x": 0.3, "y": 0.0, "z": 0.0}),
                "angular": make(Vector3, {"x": 0.0, "y": 0.0, "z": 0.2}),
            },
        )
        return make(
            Odometry,
            {
                "header": header,
                "child_frame_id": "base_link",
                "pose": make(PoseWithCovariance, {"pose": pose, "covariance": cov}),
                "twist": make(TwistWithCovariance, {"twist": twist, "covariance": cov}),
            },
        )

    def vector(make: Callable[[Any, dict[str, Any]], Any]) -> Callable[[], object]:
        return lambda: make(Vector3, {"x": 1.0, "y": 2.0, "z": 3.0})

    def odom(make: Callable[[Any, dict[str, Any]], Any]) -> Callable[[], object]:
        return lambda: odometry(make)

    ways = {"slots": slots, "setstate": state, "construct": construct, "validated": validated}
    cases: dict[str, Callable[[], object]] = {}
    for name, make in ways.items():
        cases[f"Vector3 {name}"] = vector(make)
        cases[f"Odometry {name}"] = odom(make)
    return cases


def decoding() -> dict[str, Callable[[], object]]:
    """The installed otonav's decode and Message.fast (part two)."""
    import math

    from otonav.msgs import (
        Header,
        LaserScan,
        Odometry,
        Point,
        Pose,
        PoseWithCovariance,
        TFMessage,
        Time,
        Transform,
        TransformStamped,
        Twist,
        Vector3,
    )
    from otonav.record.cdr import decode, encode

    header = Header(stamp=Time(sec=3, nanosec=40_000_000), frame_id="odom")
    odom = encode(
        Odometry(
            header=header,
            child_frame_id="base_link",
            pose=PoseWithCovariance(pose=Pose(position=Point(x=1.0, y=2.0))),
        )
    )
    scan = encode(
        LaserScan(
            header=header,
            angle_min=-math.pi,
            angle_max=math.pi,
            ranges=tuple(1.0 + i / 360 for i in range(360)),
        )
    )
    tf = encode(
        TFMessage(
            transforms=tuple(
                TransformStamped(
                    header=header,
                    child_frame_id=f"f{i}",
                    transform=Transform(translation=Vector3(x=float(i))),
                )
                for i in range(2)
            )
        )
    )
    linear, angular = Vector3(x=0.3), Vector3(z=0.1)
    return {
        "decode Odometry": lambda: decode(Odometry, odom),
        "decode LaserScan 360": lambda: decode(LaserScan, scan),
        "decode TFMessage 2": lambda: decode(TFMessage, tf),
        "Twist.fast": lambda: Twist.fast(linear=linear, angular=angular),
    }


def _child(part: str) -> None:
    """One round of ``part`` in this process: its figures as JSON on stdout."""
    cases = decoding() if part == "decoding" else construction()
    for fn in cases.values():
        _per_call(fn, 2000)  # warm: compile the decoders
    print(json.dumps({name: _per_call(fn) for name, fn in cases.items()}))


def _round(python_path: str | None) -> dict[str, float]:
    env = dict(os.environ)
    if python_path is not None:
        env["PYTHONPATH"] = python_path
    out = subprocess.run(
        [sys.executable, __file__, "--child", "decoding"],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    figures: dict[str, float] = json.loads(out)
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--baseline", help="a directory holding another otonav package")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        _child(args.child)
        return
    cases = construction()
    for fn in cases.values():
        _per_call(fn, 2000)
    runs: dict[str, list[float]] = {name: [] for name in cases}
    for _ in range(args.rounds):
        for name, fn in cases.items():
            runs[name].append(_per_call(fn))
    print(f"construction, us per message, median of {args.rounds} interleaved rounds of {N}:")
    for name, values in runs.items():
        kind = name.split()[0]
        ratio = statistics.median(values) / statistics.median(runs[f"{kind} slots"])
        print(f"  {name:<22} {statistics.median(values):7.2f} us   / slots {ratio:5.2f}")
    mine: list[dict[str, float]] = []
    theirs: list[dict[str, float]] = []
    for i in range(args.rounds):
        order = [None, args.baseline] if i % 2 == 0 else [args.baseline, None]
        for where in order:
            if where is None:
                mine.append(_round(None))
            elif args.baseline:
                theirs.append(_round(args.baseline))
    print(f"decoding, us per message, median of {args.rounds} rounds (one process each):")
    for name in mine[0]:
        here = statistics.median(r[name] for r in mine)
        line = f"  {name:<22} {here:7.2f} us"
        if theirs:
            there = statistics.median(r[name] for r in theirs)
            line += f"   baseline {there:7.2f} us   this/baseline {here / there:5.2f}"
        print(line)


if __name__ == "__main__":
    main()
