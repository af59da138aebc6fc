"""``replay(recording, actor)`` for tests: a directory of interesting recordings becomes
a regression suite.

    @pytest.mark.parametrize("recording", sorted(Path("regressions").glob("*.mcap")))
    def test_navigator_still_does_the_same(recording):
        assert replay(recording, "nav") == []
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from otonav.replay import Divergence, replay_recording
from otonav.runtime import Actor


class ReplayCrashError(AssertionError):
    """A replayed actor raised; the message is its crash report."""


def replay(
    recording: str | Path,
    actor: str | Actor | Sequence[str | Actor],
    *,
    overrides: Sequence[str] = (),
    tolerance: float = 0.0,
) -> list[Divergence]:
    """Replay ``actor`` (a stack actor's name such as ``"nav"``, ``"pkg.mod:Name"``, an
    actor object, or several) against ``recording``; return the divergences beyond
    ``tolerance`` in sim-time order (empty: it did exactly what was recorded).
    Raises :class:`ReplayCrashError` if a replayed actor crashed."""
    nodes = [actor] if isinstance(actor, str | Actor) else list(actor)
    result = replay_recording(recording, nodes, overrides=overrides, tolerance=tolerance)
    if result.crash is not None:
        raise ReplayCrashError(result.crash)
    return result.divergences
