"""SIGTERM and SIGINT to ``otonav replay --out`` (issue 41, cases 17 and 22): SIGTERM
killed it (rc -15) with a 0-byte or unindexed output left behind; SIGINT said "the
recording was finished and is readable" of a file that did not exist. Now the output
is all or nothing: a signal leaves the finished, indexed file or none (an earlier file
at that path as it was), exits 130 or 143, and says in one line which.

The signal comes from inside the process at a known point: from a replayed node at 1 s
of sim time, or from the writer at its 500th message (not at a wall-clock guess)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from otonav.record._reader import summarize
from otonav.scenario import ScenarioConfig, run_scenario

pytestmark = pytest.mark.smoke

HERE = Path(__file__).resolve().parent
CEILING_S = 120.0
NODE = "replay_signal_actor:SignalsItself"
WHILE_WRITING = """
import os, signal, sys
from otonav.record._fastwriter import FastWriter
add, written = FastWriter.add_message, [0]
def counted(self, *args, **kwargs):
    written[0] += 1
    if written[0] == 500:
        os.kill(os.getpid(), signal.Signals[os.environ["OTONAV_TEST_SIGNAL"]])
    return add(self, *args, **kwargs)
FastWriter.add_message = counted
from otonav.cli import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.fixture(scope="module")
def recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("recorded")
    run_scenario(ScenarioConfig(scene="empty", sim_budget=4.0), out_dir=out, plot=False)
    return out / "recording.mcap"


def _replay(code: str | None, argv: list[str], sig: signal.Signals) -> tuple[int, str]:
    env = {**os.environ, "OTONAV_TEST_SIGNAL": sig.name}
    env["PYTHONPATH"] = os.pathsep.join([str(HERE), env.get("PYTHONPATH", "")])
    command = [sys.executable, "-m", "otonav"] if code is None else [sys.executable, "-c", code]
    done = subprocess.run(
        [*command, "replay", *argv], env=env, capture_output=True, text=True, timeout=CEILING_S
    )
    assert "Traceback" not in done.stderr, done.stderr
    return done.returncode, done.stderr


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_while_replaying_leaves_no_output(
    recording: Path, tmp_path: Path, sig: signal.Signals
) -> None:
    out = tmp_path / "replayed.mcap"
    code, err = _replay(None, [str(recording), "--node", NODE, "--out", str(out)], sig)
    assert code == 128 + sig, err
    (line,) = err.strip().splitlines()
    assert f"{out} was not written" in line, line
    assert "finished and is readable" not in line
    assert sorted(tmp_path.iterdir()) == []  # no output, no partial file


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_while_writing_keeps_the_earlier_output(
    recording: Path, tmp_path: Path, sig: signal.Signals
) -> None:
    out = tmp_path / "replayed.mcap"
    code, err = _replay(None, [str(recording), "--node", "nav", "--out", str(out)], sig)
    assert code == 0, err
    earlier = out.read_bytes()
    assert summarize(out).truncated is False
    code, err = _replay(WHILE_WRITING, [str(recording), "--node", "nav", "--out", str(out)], sig)
    assert code == 128 + sig, err
    (line,) = err.strip().splitlines()
    assert f"{out} was not written (the earlier file there is as it was)" in line, line
    assert out.read_bytes() == earlier
    assert sorted(p.name for p in tmp_path.iterdir()) == [out.name]
