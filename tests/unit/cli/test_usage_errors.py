"""One hierarchy of errors (issue 31): bad input of every kind is a UsageError (exit 2,
one line), and every error otonav raises on purpose is an OtonavError."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.cli import main
from otonav.errors import OtonavError, UsageError
from otonav.hal._viewer import NoDisplayError
from otonav.hal.mujoco import SceneError
from otonav.record._outlock import OutputBusyError
from otonav.record._reader import RecordingError
from otonav.ros2._naming import Ros2Error
from otonav.runtime._errors import OtonavRuntimeError, SimTimeoutError
from otonav.stack._files import ConfigFileError


@pytest.mark.parametrize(
    "kind",
    [ConfigFileError, SceneError, NoDisplayError, OutputBusyError, RecordingError, Ros2Error],
)
def test_bad_input_of_every_kind_is_a_usage_error(kind: type[Exception]) -> None:
    assert issubclass(kind, UsageError)
    assert issubclass(kind, OtonavError)


def test_runtime_errors_share_the_base() -> None:
    assert issubclass(OtonavRuntimeError, OtonavError)
    assert issubclass(SimTimeoutError, OtonavError)
    assert not issubclass(OtonavRuntimeError, UsageError)  # a bug or a fault, not input


def test_a_scene_error_exits_2_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["run", "--out", str(tmp_path), "--set", "world.scene=/nonexistent/scene.xml"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.startswith("otonav: error: ")
    assert err.count("\n") == 1
