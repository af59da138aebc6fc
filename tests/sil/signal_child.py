"""Child process of the signal tests (not a test module).

    python tests/sil/signal_child.py OUT_DIR FIRST SECOND_AT [--import]

Runs ``otonav run`` (the CLI, in this process) on a scenario that does not end soon
(kp_lin = 0) and signals itself, so the timing is deterministic: FIRST (INT or TERM)
once 0.5 s of sim time have passed, then the same signal again at SECOND_AT:

- ``none``: no second signal;
- ``cancel``: right after the first, while the run is being cancelled;
- ``plot``: while the trajectory plot is drawn, after the loop has closed.

With ``--import`` it instead sends SIGINT to itself while ``otonav.cli`` is being
imported, through the console-script entry point.
"""

from __future__ import annotations

import importlib.abc
import os
import signal
import sys
from typing import Any

FIRST_AT = 0.5


class _InterruptImport(importlib.abc.MetaPathFinder):
    def find_spec(self, name: str, path: Any, target: Any = None) -> None:
        if name == "otonav.cli":
            sys.meta_path.remove(self)
            os.kill(os.getpid(), signal.SIGINT)
        return None


def main() -> int:
    if sys.argv[1] == "--import":
        sys.meta_path.insert(0, _InterruptImport())
        from otonav._entry import main as entry  # what the `otonav` script runs

        return entry()

    import otonav.scenario._artifacts as artifacts_module
    import otonav.scenario._assembly as assembly_module
    from otonav.cli import main as cli
    from otonav.scenario._judge import Judge
    from otonav.scenario._plot import plot_trajectory

    out, first, second_at = sys.argv[1], sys.argv[2], sys.argv[3]
    sig = {"INT": signal.SIGINT, "TERM": signal.SIGTERM}[first]

    class SignallingJudge(Judge):
        sent = False

        def sample(self, now: float) -> None:
            super().sample(now)
            if now >= FIRST_AT and not self.sent:
                self.sent = True
                os.kill(os.getpid(), sig)
                if second_at == "cancel":
                    os.kill(os.getpid(), sig)

    def signalling_plot(*args: Any, **kwargs: Any) -> Any:
        if second_at == "plot":
            os.kill(os.getpid(), sig)
        return plot_trajectory(*args, **kwargs)

    # Patched where a judged run looks them up.
    vars(assembly_module)["Judge"] = SignallingJudge
    vars(artifacts_module)["plot_trajectory"] = signalling_plot
    return cli(["run", "--set", "nav.kp_lin=0", "--out", out])


if __name__ == "__main__":
    raise SystemExit(main())
