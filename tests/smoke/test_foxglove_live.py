"""The live view with real WebSocket clients: every topic advertised with the recordings'
ROS 2 schemas, /odom received and decoded by mcap_ros2 equal to what was recorded; a
client that never reads, clients that come and go, and a second client neither stall
the robot nor grow memory with the traffic."""

from __future__ import annotations

import asyncio
import contextlib
import json
import socket
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import anyio
import pytest
from foxglove_client import FoxgloveClient
from websockets.asyncio.client import connect
from websockets.exceptions import InvalidStatus
from websockets.typing import Subprotocol

from otonav.cli import main as cli_main
from otonav.embed import open_live_stack
from otonav.foxglove import FoxgloveServer, LiveView, LiveViewError
from otonav.msgs import LaserScan
from otonav.record._reader import read_messages, summarize
from otonav.runtime import SENSOR_DATA_QOS, Actor, Output, RealTime, run_blocking
from otonav.scenario import ScenarioConfig, run_scenario
from otonav.stack import StackConfig
from otonav.stack._config import FoxgloveConfig
from otonav.testing import running_stack

pytestmark = pytest.mark.smoke

STACK_TOPICS = {
    "/clock", "/odom", "/imu", "/scan", "/tf", "/tf_static", "/cmd_vel", "/wheel_cmd",
    "/goal", "/nav/state", "/rosout",
}  # fmt: skip


@contextlib.contextmanager
def serving(
    backlog: int = 256, subscriptions: int = 1, wait: float | None = None
) -> Iterator[FoxgloveServer]:
    config = FoxgloveConfig(port=0, wait_for_subscriber=wait)
    server = FoxgloveServer(config, backlog=backlog, subscriptions=subscriptions)
    try:
        yield server
    finally:
        server.close()


def test_every_topic_is_advertised_and_odom_arrives_as_recorded(tmp_path: Path) -> None:
    with serving(backlog=100_000, subscriptions=3, wait=30.0) as server:
        client = FoxgloveClient(
            server.url, expect=STACK_TOPICS, subscribe={"/odom", "/tf_static", "/scan"}
        )
        live = LiveView(server)
        # The client connects now; channels appear when the run wires its actors, and
        # the live view holds sim time at the start until the client has subscribed.
        thread = threading.Thread(target=client.start)
        thread.start()
        verdict = run_scenario(
            ScenarioConfig(sim_budget=3.0), out_dir=tmp_path, plot=False, extra_actors=(live,)
        )
        thread.join()
        recording = tmp_path / "recording.mcap"
        recorded = [(round(t * 1e9), m) for _topic, t, m in read_messages(recording, ["/odom"])]
        client.wait_for("/odom", len(recorded))
        client.wait_for("/scan", 30)
        client.stop()
    assert verdict.sim_time_s == pytest.approx(3.0, abs=0.05)
    assert client.subprotocol == "foxglove.websocket.v1"
    assert client.server_info["capabilities"] == ["time", "clientPublish", "parameters"]
    types = {t.topic: t.type for t in summarize(recording).topics}
    types.pop("/scenario/verdict")  # written by the runner after the run, not a topic
    assert set(types) >= STACK_TOPICS
    assert set(types) <= set(client.channels)  # every topic of the run was advertised
    for topic in types:
        channel = client.channels[topic]
        assert (channel.encoding, channel.schema_encoding) == ("cdr", "ros2msg")
        assert channel.schema_name == types[topic]
    # /odom: every message, in order, at its sim time, decoded by mcap_ros2 from the
    # advertised schema, equal to the recording's (read by otonav's own decoder).
    odom = client.channels["/odom"]
    got = [(stamp, odom.decode(data)) for stamp, data in client.received["/odom"]]
    assert len(got) == len(recorded) >= 299

    def fields(m: Any) -> tuple[float | int, ...]:
        p = m.pose.pose.position
        return (p.x, p.y, p.z, m.twist.twist.angular.z, m.header.stamp.sec, m.header.stamp.nanosec)

    for (t_got, m_got), (t_rec, m_rec) in zip(got, recorded, strict=True):
        assert t_got == t_rec
        assert fields(m_got) == fields(m_rec)
    assert fields(got[-1][1])[0] > 0.2  # the robot moved: not a run of identical zeros
    # The latched transform arrived (the 3D panel needs it to place the scan).
    (tf_static,) = client.received["/tf_static"]
    transforms = client.channels["/tf_static"].decode(tf_static[1]).transforms
    frames = [t.child_frame_id for t in transforms]
    assert frames == ["laser", "imu_link"]
    assert len(client.received["/scan"]) == 30
    assert "/imu" not in client.received  # not subscribed: not sent
    assert client.times
    assert max(client.times) == pytest.approx(3e9, abs=5e7)  # the server's time is sim time
    assert live.statistics().dropped == 0
    # Only what a client subscribed to is encoded and sent (and latched topics).
    sent = {topic: count for topic, (count, _dropped) in live.topic_statistics().items()}
    assert (sent["/odom"], sent["/scan"], sent["/tf_static"], sent["/goal"]) == (300, 30, 1, 1)
    for topic in ("/clock", "/imu", "/tf", "/cmd_vel", "/wheel_cmd", "/nav/state", "/rosout"):
        assert sent[topic] == 0, topic


class Blaster(Actor):
    """A firehose: a 16k-beam scan (64 KiB of CDR) every 2 ms of sim time."""

    scan = Output("/blast", LaserScan, SENSOR_DATA_QOS)

    def __init__(self) -> None:
        super().__init__("blaster")
        self.message = LaserScan(ranges=tuple(float(i % 97) for i in range(16_384)))

    async def run(self) -> None:
        rate = self.clock.rate(500.0)
        while True:
            await rate.sleep()
            await self.scan.publish(self.message)


def _rss_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096


def test_slow_and_churning_clients_neither_stall_the_robot_nor_grow_memory() -> None:
    with serving(backlog=64, subscriptions=13, wait=30.0) as server:
        expect = STACK_TOPICS | {"/blast"}
        stuck = FoxgloveClient(server.url, expect=expect, read=False)  # subscribes to all
        reader = FoxgloveClient(server.url, expect=expect, subscribe={"/clock"})
        stop_churn = threading.Event()
        cycles: list[int] = []

        def churn() -> None:
            while not stop_churn.is_set():
                client = FoxgloveClient(server.url, expect={"/odom"}, subscribe={"/odom"})
                client.start()
                client.stop()
                cycles.append(1)

        live = LiveView(server)
        starters = [threading.Thread(target=c.start) for c in (stuck, reader)]
        for t in starters:
            t.start()
        churner = threading.Thread(target=churn)
        churner.start()
        rss_before = _rss_bytes()
        verdict = run_scenario(
            ScenarioConfig(sim_budget=2.0), record=False, plot=False, extra_actors=(Blaster(), live)
        )
        rss_after = _rss_bytes()
        stop_churn.set()
        churner.join(30)
        for t in starters:
            t.join()
        stuck.stop()
        reader.stop()
    # The robot ran its whole budget in sim time: nothing waited for a client.
    assert verdict.sim_time_s == pytest.approx(2.0, abs=0.05)
    assert len(cycles) >= 1
    sent = live.sent_bytes
    assert sent > 60e6  # the stuck client was offered > 60 MB it never read
    # Memory did not follow the traffic: the server keeps a bounded backlog per client.
    assert rss_after - rss_before < 0.3 * sent, (rss_after - rss_before, sent)
    # What the stuck client's backlog could not hold was dropped, and counted.
    assert live.statistics().client_dropped > 0
    # The reader kept getting /clock throughout (the stuck client did not block it).
    stamps = [t for t, _ in reader.received["/clock"]]
    assert stamps[-1] >= 1.9e9
    # The stuck client and the reader subscribed (a churning client may leave before the
    # server has registered its subscription: not counted here).
    assert live.statistics().clients_seen >= 2


def test_bad_live_view_options_are_one_line_errors(capsys: pytest.CaptureFixture[str]) -> None:
    with serving() as server, pytest.raises(LiveViewError, match="Address already in use"):
        FoxgloveServer(FoxgloveConfig(port=server.port))
    with serving() as server:
        code = cli_main(["run", "--foxglove", "--foxglove-port", str(server.port), "--no-record"])
    assert code == 2
    err = capsys.readouterr().err
    assert "pick another --foxglove-port" in err
    assert len(err.strip().splitlines()) == 1
    assert cli_main(["run", "--foxglove", "--foxglove-wait", "-1"]) == 2
    err = capsys.readouterr().err
    assert "--foxglove-wait: wait_for_subscriber: Input should be greater than 0" in err


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
    return port


def test_cli_realtime_run_serves_live(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    port = _free_port()
    codes: list[int] = []
    args = [
        "run", "--realtime", "--scale", "5", "--foxglove", "--foxglove-port", str(port),
        "--foxglove-wait", "30", "--out", str(tmp_path), "--no-record",
    ]  # fmt: skip
    run = threading.Thread(target=lambda: codes.append(cli_main(args)))
    run.start()
    client = FoxgloveClient(f"ws://127.0.0.1:{port}", expect=STACK_TOPICS, subscribe={"/clock"})
    for _attempt in range(100):  # the server starts with the command, in its thread
        try:
            client.start()
            break
        except OSError:
            run.join(0.05)  # a wall-clock ceiling for the connect retries, not a timing check
            client = FoxgloveClient(client.url, expect=STACK_TOPICS, subscribe={"/clock"})
    run.join(120)
    client.stop()
    # Exit 0 or 1: the verdict is the real-time runner's business (it slips on a busy
    # machine); what matters here is that the run served its topics while it went.
    assert codes in ([0], [1])
    assert "foxglove: serving every topic on ws://127.0.0.1:" in capsys.readouterr().err
    stamps = [t for t, _ in client.received["/clock"]]
    assert len(stamps) > 500  # /clock at 100 Hz of sim time for > 5 s
    assert stamps == sorted(stamps)
    assert max(client.times) > 5e9  # the server's time is sim time, not wall time


@pytest.mark.asyncio
async def test_open_live_stack_serves_foxglove_on_the_host_loop() -> None:
    stack = StackConfig.model_validate({"foxglove": {"enabled": True, "port": 0}})
    async with open_live_stack(stack, time=RealTime(5.0)) as live:
        server = live.foxglove
        assert server is not None
        assert server.url.startswith("ws://127.0.0.1:")
        client = FoxgloveClient(server.url, expect={"/odom", "/scan"}, subscribe={"/odom"})
        await asyncio.to_thread(client.start)
        arrived = await asyncio.to_thread(client.wait_for, "/odom", 50)
        await asyncio.to_thread(client.stop)
    assert arrived >= 50
    assert server.closed  # stopped with the stack
    stamps = [t for t, _ in client.received["/odom"]]
    assert stamps == sorted(stamps)


@pytest.mark.sim
async def test_a_pytest_stack_serves_foxglove_from_its_config() -> None:
    """running_stack wires the config's foxglove section as the CLI does (one place:
    otonav.engine); a client sees the topics at the test's sim time, and the actors'
    parameters are served."""
    stack = StackConfig.model_validate(
        {"foxglove": {"enabled": True, "port": 0, "wait_for_subscriber": 30}}
    )
    async with running_stack(stack) as running:
        server = running.foxglove
        assert server is not None
        client = FoxgloveClient(server.url, expect={"/odom"}, subscribe={"/odom"})
        await run_blocking(client.start)  # sim time holds at 0 until it subscribed
        await anyio.sleep(2.0)  # of sim time: /odom is published into the server's queue
        arrived = await run_blocking(client.wait_for, "/odom", 20)
        await run_blocking(client.stop)
        served = server.parameter_sink.get_parameters([])  # what a client's getParameters gets
    assert arrived >= 20
    assert server.closed
    assert any(p["name"].startswith("nav.params.") for p in served)


@pytest.mark.asyncio
async def test_both_names_of_the_protocol_are_accepted_and_nothing_else() -> None:
    # The specification's name (foxglove.websocket.v1) and foxglove-sdk's (foxglove.sdk.v1):
    # the same protocol; current Foxglove apps offer both, older clients only the first.
    old, new = Subprotocol("foxglove.websocket.v1"), Subprotocol("foxglove.sdk.v1")
    with serving() as server:
        for offered, expected in [([old], old), ([new], new), ([new, old], new), ([old, new], new)]:
            async with connect(server.url, subprotocols=offered) as ws:
                assert ws.subprotocol == expected
                info = json.loads(await ws.recv())
                assert info["op"] == "serverInfo"
                assert info["capabilities"] == ["time", "clientPublish", "parameters"]
        for offered in ([Subprotocol("foxglove.websocket.v2")], []):
            with pytest.raises(InvalidStatus, match="400"):
                async with connect(server.url, subprotocols=offered or None):
                    pass
