"""Child process of the held-loop tests (not a test module).

    python tests/sil/hog_child.py OUT_DIR SIGNAL

Runs ``otonav run`` (the CLI, in this process) with one extra actor, ``hog``, that at
0.5 s of sim time signals this process (INT or TERM) and then computes forever without
yielding: the signal's cancellation is a loop callback, so only the watchdog thread
can stop the run.
"""

from __future__ import annotations

import os
import signal
import sys

from otonav.runtime import Actor


class Hog(Actor):
    def __init__(self, sig: signal.Signals) -> None:
        super().__init__("hog")
        self.sig = sig

    async def run(self) -> None:
        await self.clock.sleep_until(0.5)
        os.kill(os.getpid(), self.sig)
        spins = 0
        while True:  # never yields
            spins += 1


def main() -> int:
    import otonav.cli._run as run_command
    from otonav.cli import main as cli
    from otonav.engine import Extras

    out, name = sys.argv[1], sys.argv[2]
    hog = Hog({"INT": signal.SIGINT, "TERM": signal.SIGTERM}[name])

    class HogExtras(Extras):
        @property
        def actors(self) -> tuple[Actor, ...]:
            return (hog,)

    vars(run_command)["_extras"] = lambda _stack: HogExtras()  # the CLI's extras hook
    return cli(["run", "--out", out])


if __name__ == "__main__":
    raise SystemExit(main())
