"""Writing nodes as a ROS 2 developer expects (issue 39): no __init__ for parameters,
built-ins remapped from ``actors:``, modules found next to you, ROS 2 parameter files,
and a constructor that raises or a malformed ``--actor`` as one line (issue 41)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest

from otonav.actors import topics
from otonav.cli._loading import load_stack
from otonav.hal import FakeHardware
from otonav.stack import StackConfig, build_actors
from otonav.stack._config import ActorConfig
from otonav.stack._files import ConfigFileError
from otonav.stack._launch import make_actor

pytestmark = pytest.mark.unit

PROBES = Path(__file__).resolve().parents[2] / "data" / "user_nodes" / "probe_nodes.py"
NODE = """
from otonav.runtime import Actor

class Here(Actor):
    pass
"""


def test_a_node_with_params_needs_no_init() -> None:
    actor: Any = make_actor(ActorConfig(name="tuned", class_=f"{PROBES}:Tuned", params={"gain": 2}))
    assert actor.params.gain == 2.0
    assert actor.parameters == {"gain": 2.0, "limits": {}}
    tuned: Any = type(actor)
    assert tuned().params.gain == 1.0  # built by hand: the Params defaults
    assert tuned(params=tuned.Params(gain=3.0)).params.gain == 3.0


def test_a_built_in_is_remapped_without_restating_its_class() -> None:
    entry = ActorConfig(name="nav", remap={topics.CMD_VEL_NAV: "/cmd_vel_raw"})
    actors = build_actors(StackConfig(actors=(entry,)), FakeHardware())
    nav = next(a for a in actors if a.name == "nav")
    assert type(nav).__name__ == "AvoidingNavigator"  # the built-in, kept
    assert "/cmd_vel_raw" in [nav.topic_of(p) for p in nav.ports()]
    assert topics.CMD_VEL_NAV not in [nav.topic_of(p) for p in nav.ports()]
    assert topics.ODOM in [nav.topic_of(p) for p in nav.ports()]  # the rest unchanged


@pytest.mark.parametrize(
    ("entry", "fragments"),
    [
        (ActorConfig(name="nav", remap={"/cmd_vel": "/x"}),
         ("actors.nav.remap", "no topic /cmd_vel", "/cmd_vel_nav")),
        (ActorConfig(name="nav", params={"kp": 1}), ("actors.nav.params", "nav.*")),
        (ActorConfig(name="filter", remap={"/a": "/b"}), ("actors.filter: no class",)),
    ],
)  # fmt: skip
def test_a_class_less_entry_is_checked(entry: ActorConfig, fragments: tuple[str, ...]) -> None:
    with pytest.raises(ConfigFileError) as error:
        build_actors(StackConfig(actors=(entry,)), FakeHardware())
    for fragment in fragments:
        assert fragment in str(error.value)


def test_a_module_in_the_current_directory_is_found(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "issue39_here_nodes.py").write_text(NODE)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "path", list(sys.path))
    stack = load_stack(None, [], ["issue39_here_nodes:Here"])
    (entry,) = stack.actors
    assert type(make_actor(entry)).__name__ == "Here"


def test_a_module_next_to_the_config_file_is_found(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "pkg39").mkdir()
    (tmp_path / "pkg39" / "__init__.py").write_text("")
    (tmp_path / "pkg39" / "nodes.py").write_text(NODE)
    config = tmp_path / "stack.yaml"
    config.write_text("actors:\n  - {name: here, class: 'pkg39.nodes:Here'}\n")
    monkeypatch.chdir("/")
    monkeypatch.setattr(sys, "path", list(sys.path))
    (entry,) = load_stack(config, []).actors
    assert type(make_actor(entry)).__name__ == "Here"


def test_parameters_come_from_a_ros2_params_file_under_the_inline_ones(tmp_path: Path) -> None:
    (tmp_path / "tuned.yaml").write_text(
        "/**:\n  ros__parameters: {gain: 5.0}\n"
        "tuned:\n  ros__parameters:\n    gain: 2.0\n    limits: {v: 0.5}\n"
    )
    config = tmp_path / "stack.yaml"
    config.write_text(
        f"actors:\n  - {{name: tuned, class: '{PROBES}:Tuned', params_file: tuned.yaml}}\n"
    )
    (entry,) = load_stack(config, []).actors
    assert make_actor(entry).parameters == {"gain": 2.0, "limits": {"v": 0.5}}
    (entry,) = load_stack(config, ["actors.tuned.gain=3"]).actors
    assert make_actor(entry).parameters["gain"] == 3.0  # inline wins over the file


def test_a_bad_value_in_a_params_file_names_the_file_and_its_key_path(tmp_path: Path) -> None:
    params = tmp_path / "tuned.yaml"
    params.write_text("tuned:\n  ros__parameters:\n    gain: -1.0\n")
    config = tmp_path / "stack.yaml"
    config.write_text(
        f"actors:\n  - {{name: tuned, class: '{PROBES}:Tuned', params_file: tuned.yaml}}\n"
    )
    with pytest.raises(ConfigFileError, match=rf"^{params}: tuned\.ros__parameters\.gain: "
                       r"Input should be greater than 0 \(got -1\.0\)$"):  # fmt: skip
        load_stack(config, [])
    params.write_text("other:\n  ros__parameters: {gain: 1.0}\n")
    with pytest.raises(
        ConfigFileError, match=r"no section for node 'tuned' \(its sections: other\)"
    ):
        load_stack(config, [])


def test_a_constructor_that_raises_is_one_line_with_where(tmp_path: Path) -> None:
    with pytest.raises(ConfigFileError) as error:
        make_actor(ActorConfig(name="dev", class_=f"{PROBES}:RaisesInInit"))
    assert str(error.value) == (
        "actors.dev: RaisesInInit(...) raised RuntimeError: no device /dev/ttyUSB0 "
        f"(probe_nodes.py:{_line_of('no device')})"
    )


def test_an_actor_spec_without_a_module_is_one_line() -> None:
    with pytest.raises(ConfigFileError, match=r"^--actor ':X': expected module:Class"):
        load_stack(None, [], [":X"])
    with pytest.raises(ConfigFileError, match=r"^--actor 'aaaa.*characters\): String should"):
        load_stack(None, [], ["a" * 5000 + ":Node"])


def _line_of(text: str) -> int:
    lines = PROBES.read_text().splitlines()
    return next(i for i, line in enumerate(lines, 1) if text in line)


def test_a_node_whose_params_have_required_fields_keeps_its_own_init() -> None:
    """Today's signature keeps working: ``super().__init__(name, remap=remap)`` before the
    node sets ``self.params`` itself, with a model that has no defaults to make."""
    from pydantic import BaseModel

    from otonav.runtime import Actor

    class Strict(Actor):
        class Params(BaseModel):
            speed: float

        def __init__(self, params: Params, *, name: str | None = None) -> None:
            super().__init__(name)
            self.params = params

    assert Strict(Strict.Params(speed=2.0)).params.speed == 2.0
