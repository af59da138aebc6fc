"""`make test-versions`: the unit and SIL layers under every CPython >= 3.11 on this
machine, each in its own venv, and the acceptance recording byte-identical on all.

    python3 scripts/test_versions.py [--list]

Interpreters come from pyenv (`pyenv versions`: every version it manages) and from PATH
(`python3`, `python3.N`, and the interpreter running this script); one per minor
version, pyenv's first, the newest patch release first. An interpreter without the
`venv` module cannot be used (Debian splits it into python3.N-venv).

Each version gets `.venvs/py3.N` with otonav and its dev extras pinned by constraints.txt
(what `make test` installs), made again when pyproject.toml, constraints.txt or the
interpreter change. The venvs are made one after the other on a background thread while
the layers run in those that are ready (an install mostly waits on downloads, the layers
on the CPU). In each, `scripts/gate.py unit sil` runs the two layers, then
`otonav run --scenario acceptance` writes a recording whose sha256 is compared across
versions: same config, same seed, so the same bytes on every version.

`--gate-venv .venv` (what .ci/run passes, right after `make test`): the gate has just
run every layer in that venv, so for its version the venv is used as it is, its layers
are not run a second time, and only its recording is taken.
Standard library only: it runs before any venv exists.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
VENVS = ROOT / ".venvs"
MINIMUM = (3, 11)
SCENARIO = "acceptance"
PROBE = (
    "import platform, sys, importlib.util as u; "
    "print(platform.python_implementation(), *sys.version_info[:3], "
    "u.find_spec('ensurepip') is not None and u.find_spec('venv') is not None)"
)


@dataclass(frozen=True)
class Interpreter:
    path: Path
    version: tuple[int, int, int]
    source: str  # "pyenv" or "PATH"

    @property
    def minor(self) -> str:
        return f"{self.version[0]}.{self.version[1]}"


@dataclass
class Result:
    interpreter: Interpreter
    layers_passed: bool
    seconds: float
    sha256: str | None
    run_passed: bool = False
    note: str = ""

    @property
    def passed(self) -> bool:
        return self.layers_passed and self.run_passed and self.sha256 is not None


def _pyenv_candidates() -> list[Path]:
    pyenv = shutil.which("pyenv")
    if pyenv is None:
        root = Path(os.environ.get("PYENV_ROOT", Path.home() / ".pyenv"))
        names = sorted(p.name for p in (root / "versions").glob("*")) if root.exists() else []
    else:
        root = Path(subprocess.run([pyenv, "root"], capture_output=True, text=True).stdout.strip())
        listed = subprocess.run([pyenv, "versions", "--bare"], capture_output=True, text=True)
        names = listed.stdout.split()
    return [root / "versions" / name / "bin" / "python3" for name in names if name != "system"]


def _path_candidates() -> list[Path]:
    names = ["python3", *(f"python3.{minor}" for minor in range(MINIMUM[1], 30))]
    found = [shutil.which(name) for name in names]
    return [Path(sys.executable), *(Path(p) for p in found if p is not None)]


def _probe(path: Path, source: str) -> tuple[Interpreter, bool] | None:
    if not path.exists():
        return None
    try:
        done = subprocess.run(
            [str(path), "-c", PROBE], capture_output=True, text=True, timeout=30, check=False
        )
    except (OSError, subprocess.TimeoutExpired):
        return None
    fields = done.stdout.split()
    if done.returncode != 0 or len(fields) != 5 or fields[0] != "CPython":
        return None
    version = (int(fields[1]), int(fields[2]), int(fields[3]))
    return Interpreter(path, version, source), fields[4] == "True"


def find_interpreters() -> tuple[list[Interpreter], list[str]]:
    """One usable CPython per minor version >= MINIMUM, and notes on what was passed over."""
    chosen: dict[tuple[int, int], Interpreter] = {}
    notes: list[str] = []
    seen: set[Path] = set()
    for source, paths in (("pyenv", _pyenv_candidates()), ("PATH", _path_candidates())):
        probed = [p for p in (_probe(path, source) for path in paths) if p is not None]
        for interp, has_venv in sorted(probed, key=lambda p: p[0].version, reverse=True):
            real = interp.path.resolve()
            if real in seen or interp.version[:2] < MINIMUM:
                continue
            seen.add(real)
            if interp.version[:2] in chosen:
                continue
            if not has_venv:
                notes.append(f"{interp.path} ({interp.minor}) has no venv module: not used")
                continue
            chosen[interp.version[:2]] = interp
    return [chosen[key] for key in sorted(chosen)], notes


def _stamp(interp: Interpreter) -> str:
    digest = hashlib.sha256()
    for name in ("pyproject.toml", "constraints.txt"):
        digest.update((ROOT / name).read_bytes())
    digest.update(f"{interp.path.resolve()} {interp.version}".encode())
    return digest.hexdigest()


class VenvError(Exception):
    pass


def ensure_venv(interp: Interpreter) -> Path:
    """The version's venv, made (quietly: its output is shown only if it fails) unless an
    up-to-date one exists."""
    venv = VENVS / f"py{interp.minor}"
    stamp = venv / ".installed"
    wanted = _stamp(interp)
    if stamp.exists() and stamp.read_text() == wanted:
        return venv
    shutil.rmtree(venv, ignore_errors=True)
    start = time.monotonic()
    pip = [str(venv / "bin" / "python"), "-m", "pip", "install", "--quiet"]
    for argv in (
        [str(interp.path), "-m", "venv", str(venv)],
        [*pip, "-c", "constraints.txt", "-e", ".[dev]"],
    ):
        done = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            tail = "\n".join((done.stdout + done.stderr).strip().splitlines()[-15:])
            raise VenvError(f"{' '.join(argv)}: exit {done.returncode}\n{tail}")
    stamp.write_text(wanted)
    print(f"--- made {venv.relative_to(ROOT)} in {time.monotonic() - start:.0f} s", flush=True)
    return venv


def run_version(
    interp: Interpreter, venv_ready: Future[Path], out: Path, layers: bool = True
) -> Result:
    start = time.monotonic()
    full = ".".join(map(str, interp.version))
    print(f"\n=== CPython {full} ({interp.path}): waiting for its venv ===", flush=True)
    try:
        venv = venv_ready.result()
    except VenvError as exc:
        print(f"FAILED to make the venv: {exc}", flush=True)
        return Result(interp, False, time.monotonic() - start, None, note="no venv")
    python = str(venv / "bin" / "python")
    if layers:
        print(f"=== CPython {full}: unit and sil layers ===", flush=True)
        gate = subprocess.call([python, "scripts/gate.py", "unit", "sil"], cwd=ROOT)
    else:
        print(f"=== CPython {full}: layers run by the gate in {venv}; recording only ===")
        gate = 0
    recording_dir = out / f"py{interp.minor}"
    run = subprocess.run(
        [python, "-m", "otonav", "run", "--scenario", SCENARIO, "--out", str(recording_dir)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=False,
    )
    recording = recording_dir / "recording.mcap"
    sha = hashlib.sha256(recording.read_bytes()).hexdigest() if recording.exists() else None
    note = "" if layers else f"(layers: make test, in {venv.name})"
    if run.returncode != 0:
        note = f"{SCENARIO} run: exit {run.returncode}"
    return Result(interp, gate == 0, time.monotonic() - start, sha, run.returncode == 0, note)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--list", action="store_true", help="only list the interpreters found")
    parser.add_argument(
        "--gate-venv",
        type=Path,
        help="a venv in which `make test` has just passed: its version's layers are not rerun",
    )
    args = parser.parse_args(argv)

    interpreters, notes = find_interpreters()
    gate_venv: tuple[tuple[int, int], Path] | None = None
    if args.gate_venv is not None:
        probed = _probe(args.gate_venv / "bin" / "python", "gate")
        if probed is None:
            print(f"test-versions: --gate-venv {args.gate_venv}: no CPython in it")
            return 1
        gate_venv = (probed[0].version[:2], args.gate_venv.resolve())
        if gate_venv[0] not in {i.version[:2] for i in interpreters}:
            interpreters = sorted([*interpreters, probed[0]], key=lambda i: i.version)
    for note in notes:
        print(f"test-versions: {note}")
    print("test-versions: " + ", ".join(f"{i.minor} ({i.source}: {i.path})" for i in interpreters))
    if args.list:
        return 0
    if not interpreters:
        print(f"test-versions: no CPython >= {MINIMUM[0]}.{MINIMUM[1]} with venv found")
        return 1

    with (
        tempfile.TemporaryDirectory(prefix="otonav-versions-") as tmp,
        ThreadPoolExecutor(max_workers=1) as builder,  # one install at a time, in order
    ):
        ready: list[Future[Path]] = []
        for interp in interpreters:
            if gate_venv is not None and interp.version[:2] == gate_venv[0]:
                done: Future[Path] = Future()
                done.set_result(gate_venv[1])
                ready.append(done)
            else:
                ready.append(builder.submit(ensure_venv, interp))
        results = [
            run_version(i, f, Path(tmp), layers=gate_venv is None or i.version[:2] != gate_venv[0])
            for i, f in zip(interpreters, ready, strict=True)
        ]

    shas = {r.sha256 for r in results}
    identical = len(shas) == 1 and None not in shas
    print(f"\n=== test-versions: unit + sil layers, {SCENARIO} recording sha256 ===")
    for r in results:
        verdict = "passed" if r.passed else "FAILED"
        full = ".".join(map(str, r.interpreter.version))
        print(f"{full:<8} {verdict:<7} {r.seconds:6.0f} s  {r.sha256 or '-'}  {r.note}")
    if not identical:
        print(f"FAILED: the {SCENARIO} recordings differ across versions (or one is missing)")
    failed = sum(1 for r in results if not r.passed)
    print(f"{len(results) - failed} passed, {failed} failed")
    return 0 if failed == 0 and identical else 1


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
