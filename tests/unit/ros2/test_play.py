"""``otonav play``'s reading of a recording (issue 37): the QoS each channel was recorded
with, and bad input as one line (exit 2) before anything is played."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import CliFails

from otonav.record._qos_profile import offered_qos_yaml, recorded_qos
from otonav.runtime import LATCHED_QOS, SENSOR_DATA_QOS, QoS

pytestmark = pytest.mark.unit


@pytest.mark.parametrize("qos", [QoS(depth=10), SENSOR_DATA_QOS, LATCHED_QOS, QoS(depth=100)])
def test_the_recorded_qos_is_what_the_recording_says(qos: QoS) -> None:
    assert recorded_qos(offered_qos_yaml([qos])) == qos


def test_rosbag2s_integer_enums_and_a_missing_profile() -> None:
    text = "- history: 1\n  depth: 1\n  reliability: 1\n  durability: 1\n"
    assert recorded_qos(text) == LATCHED_QOS
    assert recorded_qos("") == QoS()
    assert recorded_qos("{not: [a list") == QoS()
    assert recorded_qos("- reliability: sometimes\n") == QoS()


def test_a_file_that_is_not_a_recording_is_one_line(cli_fails: CliFails, tmp_path: Path) -> None:
    bogus = tmp_path / "notes.mcap"
    bogus.write_text("not an mcap file")
    cli_fails(["play", str(bogus)], str(bogus))


def test_a_rate_out_of_range_is_one_line(cli_fails: CliFails, tmp_path: Path) -> None:
    cli_fails(["play", str(tmp_path / "x.mcap"), "--rate", "0"], "--rate 0", "(0, 1000]")


def test_a_topic_the_recording_lacks_is_one_line(
    cli_fails: CliFails, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from otonav.cli import main

    scenario = tmp_path / "brief.yaml"
    scenario.write_text("name: brief\nscene: empty\nsim_budget: 0.5\n")
    out = tmp_path / "out"
    main(["run", "--scenario", str(scenario), "--out", str(out)])
    capsys.readouterr()
    cli_fails(
        ["play", str(out / "recording.mcap"), "--topic", "/no_such_topic"],
        "--topic /no_such_topic",
        "/odom",
    )


def test_a_damaged_recording_is_one_line_before_anything_is_played(
    cli_fails: CliFails, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from mcap.reader import make_reader

    from otonav.cli import main

    out = tmp_path / "out"
    main(["run", "--out", str(out)])
    capsys.readouterr()
    path = out / "recording.mcap"
    with path.open("rb") as f:
        summary = make_reader(f).get_summary()
    assert summary is not None
    chunk = sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)[2]
    data = bytearray(path.read_bytes())
    data[chunk.chunk_start_offset + chunk.chunk_length // 2] ^= 0xFF  # inside its records
    path.write_bytes(data)
    cli_fails(["play", str(path)], str(path), "1 damaged chunk", "CRC mismatch")
