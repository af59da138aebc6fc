"""Launch as data: the config's actors list, parameters validated against the class's
Params model, --actor, --set actors.NAME.KEY, replacing a built-in node."""

from __future__ import annotations

from pathlib import Path

import pytest

from otonav.cli._loading import load_stack
from otonav.hal import FakeHardware
from otonav.stack import StackConfig, build_actors
from otonav.stack._config import ActorConfig
from otonav.stack._files import ConfigFileError
from otonav.stack._launch import add_actors, make_actor

ROOT = Path(__file__).resolve().parents[3]
PLANNER = ROOT / "examples" / "my_nodes" / "simple_planner.py"
PROBES = ROOT / "tests" / "data" / "user_nodes" / "probe_nodes.py"


def write_config(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "stack.yaml"
    path.write_text(body)
    return path


def test_a_config_launches_a_node_from_a_file_next_to_it(tmp_path: Path) -> None:
    (tmp_path / "nodes").mkdir()
    (tmp_path / "nodes" / "planner.py").write_text(PLANNER.read_text())
    config = write_config(
        tmp_path,
        "nav: {planner: external}\n"
        "actors:\n"
        "  - {name: planner, class: nodes/planner.py:StraightToGoal, params: {max_v: 0.25}}\n",
    )
    stack = load_stack(config, [])
    actors = build_actors(stack, FakeHardware())
    planner = next(a for a in actors if a.name == "planner")
    assert type(planner).__name__ == "StraightToGoal"
    assert planner.parameters["max_v"] == 0.25  # given
    assert planner.parameters["kp_ang"] == 2.0  # the Params default
    assert "command_watch" in [a.name for a in actors]  # external planner: watched


def test_bad_parameters_are_one_line_naming_actors_name_key(tmp_path: Path) -> None:
    config = write_config(
        tmp_path,
        f"actors:\n  - {{name: planner, class: '{PLANNER}:StraightToGoal', "
        "params: {max_v: -1}}\n",
    )
    with pytest.raises(ConfigFileError, match=r"^actors\.planner\.max_v: Input should be "
                       r"greater than 0 \(got -1\)$"):  # fmt: skip
        load_stack(config, [])
    with pytest.raises(ConfigFileError, match=r"^actors\.planner\.speed: unknown parameter of "
                       r"StraightToGoal \(its parameters: max_v, kp_ang, tolerance, "
                       r"rate_hz\)"):  # fmt: skip
        load_stack(config, ["actors.planner.max_v=0.2", "actors.planner.speed=1"])


def test_set_changes_a_launched_nodes_parameter(tmp_path: Path) -> None:
    stack = load_stack(None, ["actors.straight_to_goal.max_v=0.15"], [f"{PLANNER}:StraightToGoal"])
    (entry,) = stack.actors
    assert entry.name == "straight_to_goal"
    assert entry.params == {"max_v": 0.15}
    assert make_actor(entry).parameters["max_v"] == 0.15
    with pytest.raises(ConfigFileError, match=r"^--set actors\.planner\.max_v: expected "
                       r"actors\.NAME\.PARAM with NAME one of the launched actors "
                       r"\(straight_to_goal\)$"):  # fmt: skip
        load_stack(None, ["actors.planner.max_v=1"], [f"{PLANNER}:StraightToGoal"])


def test_an_entry_named_like_a_built_in_replaces_it_in_place() -> None:
    stack = StackConfig(
        actors=(ActorConfig(name="nav", class_=f"{PROBES}:OdomCounter"),),
    )
    names = [a.name for a in build_actors(stack, FakeHardware())]
    default = [a.name for a in build_actors(StackConfig(), FakeHardware())]
    assert names == default  # same place, same name
    nav = next(a for a in build_actors(stack, FakeHardware()) if a.name == "nav")
    assert type(nav).__name__ == "OdomCounter"


@pytest.mark.parametrize(
    ("spec", "params", "message"),
    [
        ("no_such_module_xyz:Node", {}, r"^actors\.n\.class: cannot import 'no_such_module_xyz'"),
        (f"{PROBES}:Missing", {}, r"^actors\.n\.class: .* has no 'Missing' \(actor classes there: "
         r"OdomCounter, RaisesInInit, ReliableScan, ScanAsTwist, Stubborn, Tuned\)$"),
        (f"{PROBES}:NOT_AN_ACTOR", {}, r"^actors\.n\.class: .* is not an otonav\.runtime\.Actor"),
        (f"{PROBES}:OdomCounter", {"x": 1}, r"^actors\.n\.params: OdomCounter declares no "
         r"parameters \(no Params model\) but was given x$"),
        (f"{PROBES}:Stubborn", {}, r"^actors\.n\.class: Stubborn must accept params, name and "
         r"remap as keywords"),
        (f"{tmp}/nowhere.py:Node" if (tmp := "/nonexistent") else "", {},
         r"^actors\.n\.class: no file /nonexistent/nowhere\.py$"),
        ("justaname", {}, r"^actors\.n\.class: 'justaname' is not module:Class"),
    ],
)  # fmt: skip
def test_bad_classes_are_one_line_naming_the_entry(
    spec: str, params: dict[str, object], message: str
) -> None:
    with pytest.raises(ConfigFileError, match=message):
        make_actor(ActorConfig(name="n", class_=spec, params=params))


def test_actor_names_are_unique() -> None:
    with pytest.raises(
        ValueError, match=r"actors: each name once \(given more than once: \['a'\]\)"
    ):
        StackConfig.model_validate_json(
            '{"actors": [{"name": "a", "class": "m:A"}, {"name": "a", "class": "m:B"}]}'
        )
    stack = add_actors(StackConfig(), [f"{PROBES}:OdomCounter"])
    with pytest.raises(ConfigFileError, match=r"^--actor .*: an actor named 'odom_counter' is "
                       r"already launched"):  # fmt: skip
        add_actors(stack, [f"{PROBES}:OdomCounter"])


def test_the_class_key_is_written_as_class() -> None:
    entry = ActorConfig(name="n", class_="m:A")
    assert entry.model_dump()["class"] == "m:A"
    assert StackConfig.model_validate_json(
        StackConfig(actors=(entry,)).model_dump_json()
    ).actors == (entry,)


def test_recovery_speeds_respect_the_navigators_limits() -> None:
    from otonav.stack._build import navigation_params
    from otonav.stack._overrides import apply_overrides

    stack = apply_overrides(StackConfig(), ["nav.max_v=0.0001", "nav.max_omega=0.5"])
    params = navigation_params(stack, FakeHardware().geometry)
    assert params.backup_speed == 0.0001
    assert params.follow_speed == 0.0001
    assert params.spin_speed == 0.5
    default = navigation_params(StackConfig(), FakeHardware().geometry)
    rec = StackConfig().nav.recovery  # under the limits: the configured speeds, untouched
    assert (default.backup_speed, default.follow_speed, default.spin_speed) == (
        rec.backup_speed,
        rec.follow_speed,
        rec.spin_speed,
    )
