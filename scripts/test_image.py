"""`make test-image`: the container image runs otonav as a user would, and its recordings
are checked on the host with otonav's own reader.

    python scripts/test_image.py --image IMAGE [--podman CMD] [--run-options OPTIONS]

Four checks, each a real `podman run` (no network, the out directory mounted with `:U`
so the container's non-root user owns it):

1. the image's user is not root;
2. the acceptance scenario passes in the image, and its recording is byte-identical to
   the one this host's venv writes (same config, same seed, same pinned dependencies);
3. `podman stop` (SIGTERM) in the middle of a run: exit 143, the recording finished and
   indexed, the plot drawn;
4. Ctrl-C on `podman run` (SIGINT, forwarded by podman to the container): exit 130, the
   same.

Runs 3 and 4 use `--realtime` and kp_lin = 0, so the run would go on for its whole
budget (20 s of wall time) and the signal lands mid-run; the signal is sent once the
recording exists (otonav's handlers are installed by then: the entrypoint `exec`s
otonav, which is PID 1, and PID 1 ignores a SIGTERM it has no handler for).
Prints the image's size. Exit 0 when every check passed.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import shlex
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from otonav.record._reader import read_messages, summarize  # noqa: E402

SCENARIO = "acceptance"


class CheckFailed(Exception):
    pass


def _tail(text: str, lines: int = 12) -> str:
    return "\n".join(text.strip().splitlines()[-lines:])


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _check_finished(out: Path, what: str) -> float:
    """The recording is indexed (not cut off) and has sim time in it; the plot exists.
    Returns the last /clock stamp (s)."""
    recording = out / "recording.mcap"
    if not recording.exists():
        raise CheckFailed(f"{what}: no recording in {out}: {sorted(p.name for p in out.iterdir())}")
    if summarize(recording).truncated:
        raise CheckFailed(f"{what}: {recording} is cut off (no index): the run was not finished")
    clocks = [t for _topic, t, _msg in read_messages(recording, ["/clock"])]
    if not clocks or clocks[-1] < 0.5:
        raise CheckFailed(f"{what}: {recording} holds too little sim time: {clocks[-1:]} s")
    plot = out / "trajectory.png"
    if not plot.exists() or plot.stat().st_size == 0:
        raise CheckFailed(f"{what}: no trajectory plot in {out}")
    return clocks[-1]


class Podman:
    def __init__(self, podman: list[str], run_options: list[str], image: str) -> None:
        self.podman = podman
        self.run_options = run_options
        self.image = image

    def run_argv(self, out: Path, args: list[str], name: str | None = None) -> list[str]:
        named = ["--name", name] if name else []
        return [
            *self.podman,
            "run",
            "--rm",
            "--network=none",
            *named,
            *self.run_options,
            "-v",
            f"{out}:/out:U",
            self.image,
            *args,
        ]

    def inspect(self, template: str) -> str:
        done = subprocess.run(
            [*self.podman, "image", "inspect", "--format", template, self.image],
            capture_output=True,
            text=True,
            check=False,
        )
        if done.returncode != 0:
            raise CheckFailed(f"podman image inspect {self.image}: {done.stderr.strip()}")
        return done.stdout.strip()


def check_user(pm: Podman, _tmp: Path) -> str:
    user = pm.inspect("{{.Config.User}}")
    argv = [*pm.podman, "run", "--rm", "--network=none", *pm.run_options]
    done = subprocess.run(
        [*argv, "--entrypoint", "id", pm.image, "-u"],
        capture_output=True,
        text=True,
        check=False,
    )
    uid = done.stdout.strip()
    if done.returncode != 0 or uid in ("", "0") or user in ("", "0", "root"):
        raise CheckFailed(f"the image runs as root or not at all: User={user!r}, id -u: {uid!r}")
    return f"runs as {user} (id -u: {uid})"


def check_acceptance(pm: Podman, tmp: Path) -> str:
    host, box = tmp / "host", tmp / "image"
    box.mkdir()
    reference = subprocess.run(
        [sys.executable, "-m", "otonav", "run", "--scenario", SCENARIO, "--out", str(host)],
        capture_output=True,
        text=True,
        check=False,
    )
    if reference.returncode != 0:
        raise CheckFailed(f"the host's own run failed:\n{_tail(reference.stderr)}")
    done = subprocess.run(
        pm.run_argv(box, ["run", "--scenario", SCENARIO, "--out", "/out"]),
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        raise CheckFailed(
            f"{SCENARIO} in the image: exit {done.returncode}\n{_tail(done.stdout + done.stderr)}"
        )
    _check_finished(box, f"{SCENARIO} in the image")
    verdict = json.loads((box / "summary.json").read_text())
    if not verdict.get("passed"):
        raise CheckFailed(f"{SCENARIO} in the image: summary.json says {verdict}")
    ours, theirs = _sha256(box / "recording.mcap"), _sha256(host / "recording.mcap")
    if ours != theirs:
        raise CheckFailed(
            f"the image's recording differs from the host's: {ours} != {theirs} "
            "(same scenario, seed and pinned dependencies must give the same bytes)"
        )
    return f"passed; recording sha256 {ours} (the host's too)"


def _interrupted_run(pm: Podman, tmp: Path, sig: str) -> str:
    out = tmp / f"stop-{sig}"
    out.mkdir()
    name = f"otonav-test-image-{sig.lower()}-{int(time.time())}"
    args = ["run", "--scenario", SCENARIO, "--realtime", "--set", "nav.kp_lin=0"]
    proc = subprocess.Popen(
        pm.run_argv(out, [*args, "--out", "/out"], name=name),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        recording = out / "recording.mcap"
        deadline = time.monotonic() + 60.0
        while not recording.exists():
            if proc.poll() is not None or time.monotonic() > deadline:
                raise CheckFailed(f"{sig}: the run never started a recording (exit {proc.poll()})")
            time.sleep(0.1)
        time.sleep(2.0)  # some seconds of sim time (real-time mode) before the signal
        if proc.poll() is not None:
            raise CheckFailed(f"{sig}: the run ended (exit {proc.returncode}) before the signal")
        if sig == "TERM":
            # what a user, an orchestrator or a CI runner does; SIGKILL after 30 s
            subprocess.run([*pm.podman, "stop", "--time", "30", name], capture_output=True)
        else:
            proc.send_signal(signal.SIGINT)  # Ctrl-C on `podman run`; podman forwards it
        stdout, stderr = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            subprocess.run([*pm.podman, "rm", "--force", name], capture_output=True, check=False)
    expected = {"TERM": 143, "INT": 130}[sig]
    if proc.returncode != expected:
        raise CheckFailed(
            f"SIG{sig}: exit {proc.returncode}, expected {expected}\n{_tail(stdout + stderr)}"
        )
    last = _check_finished(out, f"SIG{sig}")
    if (out / "summary.json").exists():
        raise CheckFailed(f"SIG{sig}: an interrupted run must not write a summary")
    return f"exit {expected}, recording finished at {last:.2f} s of sim time, plot drawn"


def check_sigterm(pm: Podman, tmp: Path) -> str:
    return _interrupted_run(pm, tmp, "TERM")


def check_ctrl_c(pm: Podman, tmp: Path) -> str:
    return _interrupted_run(pm, tmp, "INT")


CHECKS: list[tuple[str, Callable[[Podman, Path], str]]] = [
    ("non-root user", check_user),
    (f"{SCENARIO} scenario", check_acceptance),
    ("podman stop (SIGTERM)", check_sigterm),
    ("Ctrl-C (SIGINT)", check_ctrl_c),
]


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--image", required=True)
    parser.add_argument("--podman", default="podman --runtime runc")
    parser.add_argument("--run-options", default="")
    args = parser.parse_args(argv)
    pm = Podman(shlex.split(args.podman), shlex.split(args.run_options), args.image)

    size = int(pm.inspect("{{.Size}}"))
    print(f"test-image: {args.image}, {size / 1e6:.0f} MB")
    failed = 0
    with tempfile.TemporaryDirectory(prefix="otonav-test-image-") as tmp:
        for i, (title, check) in enumerate(CHECKS):
            work = Path(tmp) / str(i)
            work.mkdir()
            start = time.monotonic()
            try:
                note = check(pm, work)
            except CheckFailed as exc:
                failed += 1
                print(f"FAILED {title}: {exc}", flush=True)
                continue
            print(f"passed {title} ({time.monotonic() - start:.1f} s): {note}", flush=True)
    print(f"{len(CHECKS) - failed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
