"""Child process of the crash-safety tests (not a test module).

    python tests/sil/crash_child.py OUT_DIR MODE

Runs a scenario that does not end on its own soon (kp_lin = 0, the longest budget) recording to
OUT_DIR/recording.mcap, prints ``ready`` once 30 s of sim time have passed, then either
waits to be signalled (MODE=wait) or has an actor raise (MODE=raise).
"""

from __future__ import annotations

import sys
from pathlib import Path

from otonav.runtime import Actor
from otonav.scenario import ScenarioConfig, run_scenario
from otonav.stack import NavConfig, StackConfig

READY_AT = 30.0


class Marker(Actor):
    def __init__(self, mode: str) -> None:
        super().__init__("marker")
        self.mode = mode

    async def run(self) -> None:
        await self.clock.sleep_until(READY_AT)
        print("ready", flush=True)
        if self.mode == "raise":
            raise RuntimeError(f"injected fault at {READY_AT} s")


def main() -> None:
    out, mode = Path(sys.argv[1]), sys.argv[2]
    run_scenario(
        ScenarioConfig(sim_budget=1800.0),  # the most allowed; signalled at 30 s
        StackConfig(nav=NavConfig(planner="stop", kp_lin=0.0)),
        out_dir=out,
        plot=False,
        wall_ceiling=None,
        extra_actors=(Marker(mode),),
    )


if __name__ == "__main__":
    main()
