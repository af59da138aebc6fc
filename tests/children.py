"""Child processes started as a terminal starts them (issue 43).

A shell without job control starts a background command (``make test &``, a CI runner's
step, ``nohup``) with SIGINT and SIGQUIT ignored, and an ignored disposition survives
``exec``. Python installs its KeyboardInterrupt handler only over the default, so a child
of such a suite never sees Ctrl-C: the signal tests' children ran to their end (exit 0)
or went on importing. Every test that sends a child SIGINT, or has it send one to itself,
starts it with :func:`terminal_signals`, so its verdict does not depend on how the suite
was started.
"""

from __future__ import annotations

import signal


def terminal_signals() -> None:
    """``preexec_fn``: SIGINT and SIGQUIT at their defaults, as in a foreground command."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGQUIT, signal.SIG_DFL)
