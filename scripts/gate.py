"""The test gate: four layers, cheapest first, stopping at the first red one.

    python scripts/gate.py            # all layers
    python scripts/gate.py static     # only the named layers, in gate order

Each layer prints its wall time. The same script runs for people (`make test`) and CI
(`.ci/run`).

Two conditions a test must not depend on are fixed here, so that a test that does fails
on every run instead of at random (issue 43):

- the order: pytest-randomly shuffles each layer's tests with a seed the gate prints
  (``GATE_SEED=N`` repeats a gate's orders; ``pytest tests/sil -p randomly
  --randomly-seed=N`` one layer's, ``-p no:randomly`` runs the files' own order);
- the process: the unit, smoke and SIL layers run on two pytest-xdist workers, so a test
  that shares state with another one in its process fails too;
- how the gate was started: each layer runs with SIGINT ignored, as a shell without job
  control starts ``make test &`` or a CI step. A test whose child must see Ctrl-C starts
  it with ``tests/children.py``'s ``terminal_signals``. Ctrl-C on the gate still stops
  the layer: gate.py receives it and ends the layer's process.
"""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PY = sys.executable
BIN = Path(PY).parent
# The shell the project runs: its scripts, CI's entry point (and, through actionlint,
# the workflow's run: steps).
SHELL_SCRIPTS = [*sorted(str(p.relative_to(ROOT)) for p in ROOT.glob("scripts/*.sh")), ".ci/run"]

WORKERS = ["-n", str(min(2, os.cpu_count() or 1))]
"""pytest-xdist: the unit, smoke and SIL layers on (up to) two cores; the sims run in
virtual time, so they are CPU-bound and halve (SIL 206 -> 101 s on this machine)."""

LAYERS: dict[str, list[list[str]]] = {
    "static": [
        [PY, "-m", "ruff", "check", "."],
        [PY, "-m", "ruff", "format", "--check", "."],
        [PY, "-m", "mypy"],
        [str(BIN / "lint-imports")],
        # delivery: the Containerfile, the CI workflow, the shell scripts (docs/adr/0049)
        [str(BIN / "hadolint"), "Containerfile"],
        [str(BIN / "actionlint"), "-shellcheck", str(BIN / "shellcheck")],
        [str(BIN / "shellcheck"), *SHELL_SCRIPTS],
        [PY, "-m", "pytest", "tests/static", "-q"],
    ],
    "unit": [[PY, "-m", "pytest", "tests/unit", "-q", *WORKERS]],
    "smoke": [[PY, "-m", "pytest", "tests/smoke", "tests/embed", "-q", *WORKERS]],
    "sil": [[PY, "-m", "pytest", "tests/sil", "-q", *WORKERS]],
}


def _as_in_the_background() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def main(argv: list[str]) -> int:
    wanted = argv or list(LAYERS)
    unknown = [name for name in wanted if name not in LAYERS]
    if unknown:
        print(f"gate: unknown layer(s) {unknown}; valid: {list(LAYERS)}", file=sys.stderr)
        return 2
    given = os.environ.get("GATE_SEED", "")
    if given and not given.isdigit():
        print(f"gate: GATE_SEED={given!r} is not a whole number", file=sys.stderr)
        return 2
    seed = int(given) if given else random.randrange(1, 2**31)
    print(f"gate: tests in random order, GATE_SEED={seed} repeats it", flush=True)
    timings: list[tuple[str, float]] = []
    for name in (layer for layer in LAYERS if layer in wanted):
        print(f"\n=== layer {name} ===", flush=True)
        start = time.perf_counter()
        for cmd in LAYERS[name]:
            if "pytest" in cmd:
                cmd = [*cmd, f"--randomly-seed={seed}"]
            print("$ " + " ".join(Path(c).name if c == PY else c for c in cmd), flush=True)
            code = subprocess.call(cmd, cwd=ROOT, preexec_fn=_as_in_the_background)
            if code != 0:
                elapsed = time.perf_counter() - start
                print(f"\n=== layer {name} FAILED after {elapsed:.1f} s (exit {code}) ===")
                return 1
        timings.append((name, time.perf_counter() - start))
        print(f"=== layer {name} passed in {timings[-1][1]:.1f} s ===", flush=True)
    print("\ngate passed: " + ", ".join(f"{n} {t:.1f} s" for n, t in timings))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
