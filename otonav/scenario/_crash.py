"""A scenario run that ended with an actor's crash still has a verdict (issue 27 item 8).

:func:`~otonav.scenario._run.run_scenario` raises :class:`RunCrashedError`, an
:class:`~otonav.runtime.ActorCrashedError` (code catching that keeps working) that also
carries the run's failed :class:`~otonav.scenario._verdict.Verdict`: its artifacts were
written on the way out, and a host (the CLI) prints the table and the summary from it.
The verdict's reason is one line (:func:`crash_reason`); the traceback is on /rosout.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from otonav.runtime import ActorCrashedError

if TYPE_CHECKING:
    from otonav.scenario._verdict import Verdict

__all__ = ("RunCrashedError", "crash_reason")


class RunCrashedError(ActorCrashedError):
    """An actor crashed and stopped the run; ``verdict`` is the run's (failed) verdict,
    whose artifacts (recording, plot) exist. The actor's exception is the ``__cause__``."""

    def __init__(self, crash: ActorCrashedError, verdict: Verdict) -> None:
        super().__init__(crash.actor, crash.sim_time, crash.traceback_text)
        self.verdict = verdict


def crash_reason(crash: ActorCrashedError) -> str:
    """``actor 'nav' crashed at sim time 3.000 s: RuntimeError: boom``: the message's
    first clause and the exception the traceback ended with, on one line."""
    lines = [line.strip() for line in crash.traceback_text.splitlines() if line.strip()]
    last = lines[-1] if lines else "no traceback"
    return f"actor '{crash.actor}' crashed at sim time {crash.sim_time:.3f} s: {last}"
