"""The example service against hostile clients (issue 41, cases 5, 6 and 19), started for
real (a subprocess on an ephemeral port) and driven over real TCP connections:

- every path-valued key of the config schemas (found by walking the schemas, not listed
  by hand) is refused by the allow-list of what a client may set, with the same answer
  whether the file exists or not, and nothing a client names is read, imported or run;
- 200 slowloris connections (headers or a body trickled) at a 200-descriptor ulimit:
  /health keeps answering, every slow connection is closed by the server, the log stays
  short and has no traceback;
- a client that goes away in the middle of its body leaves no traceback in the log."""

from __future__ import annotations

import contextlib
import importlib.util
import re
import resource
import selectors
import shutil
import signal
import socket
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import httpx
import pytest

from otonav import limits
from otonav.scenario import ScenarioConfig
from otonav.stack import StackConfig

pytestmark = pytest.mark.smoke

APP = Path(__file__).resolve().parents[2] / "examples" / "service" / "app.py"
CEILING_S = 30.0
"""Hang ceiling for anything the server should do (start, answer, close a connection)."""
TIMEOUT_S = 1.0
"""The server's header and body timeouts in these tests (its defaults are longer)."""
MAX_CONNECTIONS = 32
ATTACKERS = 200
NOFILE = 200
"""The service's descriptor limit: the attack alone would use every one."""


@dataclass(frozen=True, slots=True)
class Server:
    url: str
    host: str
    port: int
    log: Path


@contextlib.contextmanager
def _serve(out: Path) -> Iterator[Server]:
    """The service (no live robot) with short timeouts and a descriptor limit. On exit it
    is stopped by SIGTERM; its log must have no traceback and stay short."""

    def limit_descriptors() -> None:
        _soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
        resource.setrlimit(resource.RLIMIT_NOFILE, (NOFILE, hard))

    out.mkdir(exist_ok=True)
    log = out / "stderr.log"
    with log.open("w") as stderr:
        process = subprocess.Popen(
            [
                *(sys.executable, str(APP), "--port", "0", "--out", str(out), "--no-live"),
                *("--header-timeout", str(TIMEOUT_S), "--body-timeout", str(TIMEOUT_S)),
                *("--max-connections", str(MAX_CONNECTIONS)),
            ],
            stdout=subprocess.PIPE,
            stderr=stderr,
            text=True,
            cwd=out,
            preexec_fn=limit_descriptors,
        )
        try:
            assert process.stdout is not None
            with selectors.DefaultSelector() as selector:
                selector.register(process.stdout, selectors.EVENT_READ)
                assert selector.select(CEILING_S), "the service printed no address"
            url = process.stdout.readline().split()[-1]
            host, port = url.removeprefix("http://").split(":")
            yield Server(url, host, int(port), log)
        finally:
            process.send_signal(signal.SIGTERM)
            try:
                code = process.wait(timeout=CEILING_S)
            finally:
                if process.poll() is None:
                    process.kill()
                if process.stdout is not None:
                    process.stdout.close()
    text = log.read_text()
    assert code == 128 + signal.SIGTERM, text[-2000:]
    assert "Traceback" not in text, text[-4000:]
    assert len(text) < 4000, f"{len(text)} bytes of log: {text[:2000]}"


# -- the schemas' keys -------------------------------------------------------------------


def _leaves(schema: dict[str, Any]) -> Iterator[tuple[str, dict[str, Any]]]:
    """(dotted key, leaf schema) of every key a ``--set`` can name: sections are walked
    (an optional section too), a list is one key."""
    defs = schema.get("$defs", {})

    def resolve(node: dict[str, Any]) -> dict[str, Any]:
        while "$ref" in node:
            node = defs[node["$ref"].rsplit("/", 1)[-1]]
        return node

    def walk(node: dict[str, Any], prefix: str) -> Iterator[tuple[str, dict[str, Any]]]:
        for name, sub in node["properties"].items():
            sub = resolve(sub)
            options = [resolve(o) for o in sub.get("anyOf", [sub]) if o.get("type") != "null"]
            sections = [o for o in options if "properties" in o]
            if sections:
                yield from walk(sections[0], f"{prefix}{name}.")
            else:
                yield f"{prefix}{name}", {**sub, "anyOf": options, "$defs": defs}

    yield from walk(resolve(schema), "")


def _holds_a_path(leaf: dict[str, Any]) -> bool:
    """A string the schema bounds as a path (``limits.MAX_PATH_CHARS``), here or in the
    items of a list (the ``class`` of an ``actors`` entry)."""
    defs = leaf["$defs"]

    def search(node: Any) -> bool:
        if isinstance(node, dict):
            if "$ref" in node:
                return search(defs[node["$ref"].rsplit("/", 1)[-1]])
            if node.get("type") == "string" and node.get("maxLength") == limits.MAX_PATH_CHARS:
                return True
            return any(search(v) for k, v in node.items() if k != "$defs")
        if isinstance(node, list):
            return any(search(v) for v in node)
        return False

    return search({k: v for k, v in leaf.items() if k != "$defs"})


STACK_KEYS = dict(_leaves(StackConfig.model_json_schema(by_alias=True)))
SCENARIO_KEYS = dict(_leaves(ScenarioConfig.model_json_schema(by_alias=True)))
PATH_KEYS = sorted(key for key, leaf in STACK_KEYS.items() if _holds_a_path(leaf))
SCENARIO_PATH_KEYS = sorted(key for key, leaf in SCENARIO_KEYS.items() if _holds_a_path(leaf))


def test_the_schema_walk_finds_the_known_path_keys() -> None:
    """The walk is what the refusal test relies on: it must find at least these."""
    assert {"robot.model", "world.scene", "actors"} <= set(PATH_KEYS), PATH_KEYS
    assert SCENARIO_PATH_KEYS == ["scene"]
    assert len(STACK_KEYS) > 150  # every section was entered


def test_the_readme_says_what_a_client_may_set() -> None:
    """The README's list is the allow-list the code enforces, key for key."""
    spec = importlib.util.spec_from_file_location("otonav_service_app_hostile", APP)
    assert spec is not None
    assert spec.loader is not None
    app = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = app  # its dataclasses look their module up
    spec.loader.exec_module(app)
    readme = (APP.parent / "README.md").read_text()
    allowed = readme.split("allow-list and nothing else:")[1].split("(numbers")[0]
    listed = re.findall(r"`([^`]+)`", allowed)
    assert listed == list(app.CLIENT_KEYS)


def _plant(where: Path) -> dict[str, Path]:
    """Files a client might name: an MJCF with a secret body name, a node that leaves a
    mark when imported, and a path that does not exist."""
    where.mkdir()
    model = where / "secret.xml"  # names of one length: errors quote them cut alike
    model.write_text(
        '<mujoco><worldbody><body name="SECRET_BODY"><freejoint/>'
        '<geom type="box" size=".1 .1 .1"/></body></worldbody></mujoco>'
    )
    node = where / "planted.py"
    node.write_text(
        f"from pathlib import Path\nPath({str(where / 'IMPORTED')!r}).touch()\n"
        "class Planted:\n    pass\n"
    )
    return {"model": model, "node": node, "missing": where / "absent.xml"}


def _value(key: str, path: Path) -> str:
    if key == "actors":
        return f"[{{name: planted, class: '{path}:Planted'}}]"
    return str(path)


@pytest.mark.timeout(300)
def test_no_key_a_client_sets_reads_a_file(tmp_path: Path) -> None:
    """Case 5: ``robot.model=PATH`` made the server read the file, said whether it
    existed, put a planted MJCF's body names in its errors and ran a server-side model.
    Every key of the stack schema is set to an existing file and to a missing one: the
    answers are 400s that are the same but for the path; the path-valued keys are
    refused as keys a client may not set; nothing planted was read or imported."""
    planted = _plant(tmp_path / "planted")
    with _serve(tmp_path / "out") as server, httpx.Client(base_url=server.url) as client:

        def error(body: dict[str, Any]) -> str:
            response = client.post("/runs", json=body, timeout=CEILING_S)
            assert response.status_code == 400, (body, response.status_code, response.text)
            message: str = response.json()["error"]
            assert "SECRET_BODY" not in message
            return message

        for key in STACK_KEYS:
            for name in ("model", "node"):
                real = error({"set": [f"{key}={_value(key, planted[name])}"]})
                missing = error({"set": [f"{key}={_value(key, planted['missing'])}"]})
                same = real.replace(str(planted[name]), "P")
                assert same == missing.replace(str(planted["missing"]), "P"), key
            if key in PATH_KEYS:
                assert "not a key a client may set" in real, (key, real)
        for key in SCENARIO_PATH_KEYS:
            said = [error({"scenario": {key: str(planted[n])}}) for n in ("model", "missing")]
            assert said[0].replace(str(planted["model"]), "P") == said[1].replace(
                str(planted["missing"]), "P"
            )
            assert "reads no files" in said[0]
        # What is allowed still works: a tuning number is taken.
        taken = client.post("/runs", json={"set": ["nav.kp_lin=0.4"], "scenario": "empty"})
        assert taken.status_code == 202, taken.text
        client.delete(f"/runs/{taken.json()['id']}", timeout=CEILING_S)
    assert not (tmp_path / "planted" / "IMPORTED").exists()


# -- slow clients ------------------------------------------------------------------------


def _connect(server: Server) -> socket.socket:
    sock = socket.create_connection((server.host, server.port), timeout=CEILING_S)
    sock.setblocking(False)
    return sock


def _closed_by_server(sock: socket.socket) -> bool:
    """Read what is there; True once the server closed (EOF or reset)."""
    try:
        while data := sock.recv(65536):
            del data
    except BlockingIOError:
        return False
    except OSError:
        return True
    return True


def _health(server: Server) -> None:
    response = httpx.get(f"{server.url}/health", timeout=CEILING_S)
    assert response.status_code == 200, response.text
    assert response.json()["status"] == "ok"


@pytest.mark.timeout(300)
def test_slowloris_on_headers_and_bodies_keeps_health_answering(tmp_path: Path) -> None:
    """Case 6: 200 connections trickling headers or a body took every descriptor, /health
    was down for the whole attack and the log took 75,772 tracebacks. Now /health
    answers throughout, and the server closes every slow connection itself (the
    attackers keep trickling a byte whenever nothing came back for a while: a header
    deadline is not reset by trickling)."""
    head = b"POST /runs HTTP/1.1\r\nHost: x\r\n"
    with _serve(tmp_path) as server:
        attackers: list[socket.socket] = []
        try:
            for i in range(ATTACKERS):
                sock = _connect(server)
                attackers.append(sock)
                if i % 2:  # a whole head, then a body that never ends
                    sock.send(head + b"Content-Type: application/json\r\n")
                    sock.send(b"Content-Length: 100000\r\n\r\n{")
                else:  # a head that never ends
                    sock.send(head + b"X-Slow: 1\r\n")
                if i % 20 == 19:
                    _health(server)
            _health(server)
            open_ = set(attackers)
            with selectors.DefaultSelector() as selector:
                for sock in attackers:
                    selector.register(sock, selectors.EVENT_READ, sock)
                rounds = 0
                while open_:
                    rounds += 1
                    assert rounds <= CEILING_S * 2, f"{len(open_)} slow connections still open"
                    ready = selector.select(0.5)
                    for key, _ in ready:
                        sock = key.data
                        if sock in open_ and _closed_by_server(sock):
                            open_.discard(sock)
                            selector.unregister(sock)
                    if not ready:  # trickle: one more byte from each
                        for sock in open_:
                            with contextlib.suppress(OSError):
                                sock.send(b"x")
                    _health(server)
        finally:
            for sock in attackers:
                sock.close()
        _health(server)


@pytest.mark.timeout(120)
def test_a_client_leaving_mid_body_leaves_no_traceback(tmp_path: Path) -> None:
    """Case 19: a client that disconnects in the middle of its body put "Exception in
    ASGI application" and a traceback in the log (checked when the server stops)."""
    with _serve(tmp_path) as server:
        sock = socket.create_connection((server.host, server.port), timeout=CEILING_S)
        sock.sendall(b'POST /runs HTTP/1.1\r\nHost: x\r\nContent-Length: 1000\r\n\r\n{"scen')
        sock.close()
        _health(server)


@pytest.mark.timeout(120)
def test_a_run_whose_directory_is_removed_ends_in_one_line(tmp_path: Path) -> None:
    """Issue 41, case 16, through the service: the run's directory removed while it runs
    is the run's error (one line), not a traceback in the log, not a success."""
    endless = {
        "name": "endless",
        "scene": "empty",
        "goal": {"x": 3.0, "y": -1.0},
        "goal_tolerance": 0.001,
        "sim_budget": 60.0,  # it runs to its budget: a second or two of wall time
    }
    with _serve(tmp_path) as server, httpx.Client(base_url=server.url) as client:
        run_id = client.post("/runs", json={"scenario": endless}).json()["id"]
        for _ in range(int(CEILING_S * 20)):  # until it has run a second of sim time
            run = client.get(f"/runs/{run_id}", params={"wait": 0.05}).json()
            if (run["sim_time_s"] or 0.0) >= 1.0:
                break
        shutil.rmtree(tmp_path / "runs" / run_id)
        run = client.get(f"/runs/{run_id}", params={"wait": CEILING_S}, timeout=2 * CEILING_S)
        run = run.json()
        assert run["status"] == "error", run
        assert "the recording was deleted while the run wrote it" in run["error"]
        assert "\n" not in run["error"]


def test_a_connection_cap_above_the_descriptor_limit_is_refused(tmp_path: Path) -> None:
    """The cap keeps accept() from failing (a traceback per attempt): one above what the
    descriptors allow is refused at start, in one line."""

    def limit_descriptors() -> None:
        _soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
        resource.setrlimit(resource.RLIMIT_NOFILE, (NOFILE, hard))

    done = subprocess.run(
        [
            *(sys.executable, str(APP), "--port", "0", "--out", str(tmp_path), "--no-live"),
            *("--max-connections", str(NOFILE)),
        ],
        capture_output=True,
        text=True,
        timeout=CEILING_S,
        preexec_fn=limit_descriptors,
    )
    assert done.returncode == 2, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert f"--max-connections {NOFILE}: more than this process's descriptor limit" in line
    assert f"ulimit -n {NOFILE}" in line
