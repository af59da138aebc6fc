"""Comparing replayed outputs with recorded ones, topic by topic.

Messages are paired by instant: the k-th message a topic got at sim time t in the
recording with the k-th the replay published at t. A pair whose CDR bytes are equal is
identical; otherwise both are decoded and compared field by field (floats within an
absolute tolerance; NaN equals NaN). A message at an instant the other side has none is
``missing`` (recorded, not replayed) or ``extra`` (replayed, not recorded): a change in
count or timing.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import Any, Literal, NamedTuple

from otonav.msgs import Message
from otonav.record.cdr import decode, encode
from otonav.replay._recording import RecordedMessage

Kind = Literal["content", "missing", "extra"]


@dataclass(frozen=True, slots=True)
class Divergence:
    """One replayed message that differs from the recording beyond the tolerance."""

    topic: str
    sim_time: float
    """Seconds of sim time (the recorded instant; the replayed one for ``extra``)."""
    kind: Kind
    index: int
    """Which message of the topic (0-based) on the side it comes from."""
    field: str = ""
    """Dotted path of the first differing field (``content`` only), e.g. ``angular.z``."""
    recorded: Any = None
    replayed: Any = None

    def __str__(self) -> str:
        where = f"{self.topic} at sim time {self.sim_time:.3f} s"
        if self.kind == "missing":
            return f"{where}: recorded message #{self.index} has no replayed counterpart"
        if self.kind == "extra":
            return f"{where}: replayed message #{self.index} was not in the recording"
        return (
            f"{where} (message #{self.index}): {self.field} recorded {self.recorded!r}, "
            f"replayed {self.replayed!r}"
        )


@dataclass(slots=True)
class TopicComparison:
    """Per-topic summary."""

    topic: str
    recorded: int
    replayed: int
    identical: int = 0
    """Pairs with byte-identical CDR."""
    within_tolerance: int = 0
    """Pairs that differ, but only in floats within the tolerance."""
    differing: int = 0
    """Pairs that differ beyond the tolerance."""
    missing: int = 0
    extra: int = 0
    max_abs_diff: float = 0.0
    """Largest absolute difference of a numeric field over the pairs."""
    max_diff_field: str = ""
    max_diff_values: tuple[Any, Any] | None = None
    """(recorded, replayed) at ``max_diff_field``: what to print when the field is not a
    number (its difference counts as inf)."""
    first: Divergence | None = None

    @property
    def diverged(self) -> bool:
        return self.first is not None

    @property
    def byte_identical(self) -> bool:
        return self.recorded == self.replayed == self.identical


class Replayed(NamedTuple):
    """A message a replayed actor published. (A named tuple: one per output, 773 for
    the navigator on the acceptance recording.)"""

    topic: str
    time_ns: int
    message: Message


def compare_topic(
    topic: str,
    msg_type: type[Message],
    recorded: Sequence[RecordedMessage],
    replayed: Sequence[Replayed],
    tolerance: float,
    divergences: list[Divergence],
) -> TopicComparison:
    """Compare one topic; append each divergence beyond ``tolerance`` to ``divergences``."""
    summary = TopicComparison(topic, len(recorded), len(replayed))

    def diverge(d: Divergence) -> None:
        divergences.append(d)
        if summary.first is None:
            summary.first = d

    i = j = 0
    while i < len(recorded) or j < len(replayed):
        r = recorded[i] if i < len(recorded) else None
        p = replayed[j] if j < len(replayed) else None
        if p is None or (r is not None and r.time_ns < p.time_ns):
            assert r is not None
            summary.missing += 1
            diverge(Divergence(topic, r.time_ns / 1e9, "missing", i))
            i += 1
            continue
        if r is None or p.time_ns < r.time_ns:
            summary.extra += 1
            diverge(Divergence(topic, p.time_ns / 1e9, "extra", j, replayed=p.message))
            j += 1
            continue
        data = encode(p.message)
        if data == r.data:
            summary.identical += 1
        else:
            # Compare what is on the wire on both sides (a float32 field is rounded).
            old, new = decode(msg_type, r.data), decode(msg_type, data)
            first: tuple[str, Any, Any] | None = None
            for path, a, b, diff in _differences(old, new):
                if diff > summary.max_abs_diff:
                    summary.max_abs_diff, summary.max_diff_field = diff, path
                    summary.max_diff_values = (a, b)
                if first is None and not diff <= tolerance:
                    first = (path, a, b)
            if first is None:
                summary.within_tolerance += 1
            else:
                summary.differing += 1
                diverge(Divergence(topic, r.time_ns / 1e9, "content", i, *first))
        i += 1
        j += 1
    return summary


def _differences(a: Any, b: Any, path: str = "") -> Iterator[tuple[str, Any, Any, float]]:
    """``(path, a, b, |a - b|)`` for every leaf where ``a`` and ``b`` differ (inf for
    non-numeric leaves, lengths, and a NaN against a number)."""
    if isinstance(a, Message) and isinstance(b, Message):
        for name in type(a).model_fields:
            yield from _differences(
                getattr(a, name), getattr(b, name), f"{path}.{name}" if path else name
            )
        return
    if isinstance(a, tuple) and isinstance(b, tuple):
        if len(a) != len(b):
            yield f"{path} (length)", len(a), len(b), math.inf
            return
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            yield from _differences(x, y, f"{path}[{k}]")
        return
    if isinstance(a, float) and isinstance(b, float):
        if a == b or (math.isnan(a) and math.isnan(b)):
            return
        diff = abs(a - b)
        yield path, a, b, diff if not math.isnan(diff) else math.inf
        return
    if a != b:
        numeric = isinstance(a, int | float) and isinstance(b, int | float)
        numeric = numeric and not isinstance(a, bool) and not isinstance(b, bool)
        yield path, a, b, float(abs(a - b)) if numeric else math.inf
