"""The pytest plugin keeps a failing scenario test's recording under a known directory,
draws its trajectory, and names both in the failure report; a passing test keeps none."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.record._reader import summarize

pytestmark = pytest.mark.sil

USER_TEST = """
import pytest
from otonav.actors import topics
from otonav.msgs import PoseStamped, Pose, Point
from otonav.runtime import LATCHED_QOS, until
from otonav.stack import NavConfig, StackConfig
from otonav.testing import running_stack


async def _go(artifacts, kp_lin):
    config = StackConfig(nav=NavConfig(planner="stop", kp_lin=kp_lin))
    async with running_stack(config, record_to=artifacts / "recording.mcap") as stack:
        goal = stack.system.publisher(topics.GOAL, PoseStamped, LATCHED_QOS)
        await goal.publish(PoseStamped(pose=Pose(position=Point(x=4.0, y=1.5))))
        truth = stack.hal.ground_truth
        await until(lambda: (truth().x - 4.0) ** 2 + (truth().y - 1.5) ** 2 < 0.15**2, within=20.0)


@pytest.mark.sim
async def test_broken_gain(otonav_artifacts):
    await _go(otonav_artifacts, 0.0)


@pytest.mark.sim
async def test_good_gain(otonav_artifacts):
    await _go(otonav_artifacts, 0.8)
"""


def test_failing_scenario_test_keeps_and_names_its_recording(pytester: pytest.Pytester) -> None:
    pytester.makepyfile(test_user=USER_TEST)
    artifacts = pytester.path / "kept"
    result = pytester.runpytest_subprocess(
        f"--otonav-artifacts={artifacts}", "-p", "no:cacheprovider"
    )
    result.assert_outcomes(passed=1, failed=1)
    result.stdout.fnmatch_lines(
        ["*otonav artifacts*", "*recording: *recording.mcap*", "*trajectory: *.png*"]
    )
    # The failure says why in sim time: the budget, the sim time, the last value.
    result.stdout.fnmatch_lines(["*not met within 20 s of sim time*"])
    kept = sorted(p.relative_to(artifacts) for p in artifacts.rglob("*") if p.is_file())
    assert kept == [
        Path("test_user.py_test_broken_gain/recording.mcap"),
        Path("test_user.py_test_broken_gain/trajectory.png"),
    ]
    recording = artifacts / kept[0]
    summary = summarize(recording)
    assert not summary.truncated
    assert summary.duration_s == pytest.approx(20.0, abs=0.05)


SHORT_FAILURES = """
import pytest
from otonav.runtime import until
from otonav.stack import StackConfig
from otonav.stack._config import ActorConfig
from otonav.testing import running_stack

PROBES = {probes!r}


@pytest.mark.sim
async def test_wait_runs_out(otonav_artifacts):
    async with running_stack(StackConfig(), record_to=otonav_artifacts / "run.mcap") as stack:
        truth = stack.hal.ground_truth
        await until(lambda: truth().x > 3.0, within=1.0, observe=lambda: round(truth().x, 2))


@pytest.mark.sim
async def test_miswired_node():
    config = StackConfig(actors=(ActorConfig(name="n", class_=PROBES + ":ScanAsTwist"),))
    async with running_stack(config):
        pass
"""


def test_a_failed_wait_and_a_wiring_error_are_short(pytester: pytest.Pytester) -> None:
    """Issue 39 item 9: ~100 lines, mostly the source of waits.py, became the predicate,
    its last observed value, the sim time and the test's own line, plus the artifacts."""
    probes = Path(__file__).resolve().parents[1] / "data" / "user_nodes" / "probe_nodes.py"
    pytester.makepyfile(test_user=SHORT_FAILURES.format(probes=str(probes)))
    result = pytester.runpytest_subprocess(
        f"--otonav-artifacts={pytester.path / 'kept'}",
        "-p",
        "no:cacheprovider",
        "-p",
        "no:randomly",
    )
    result.assert_outcomes(failed=2)
    out = result.stdout.str()
    report = out[out.index("= FAILURES =") : out.index("short test summary")]
    assert len(report.splitlines()) <= 12, report
    assert "def until" not in report
    assert "waits.py" not in report
    result.stdout.fnmatch_lines(
        [
            "*test_user.py:14: SimTimeoutError: truth().x > 3.0 not met within 1 s of sim time "
            "(gave up at sim time 1.000 s; last observed: *)",
            "*recording: *run.mcap*",
            "*test_user.py:*: TopicTypeError: n.scan wants topic '/scan' as *Twist*",
        ]
    )
