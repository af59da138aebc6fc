"""Sweep files: a valid one expands into the runs it names (in order, each once, with
ids that do not depend on anything but what runs); a broken one is exit 2 with one line
naming the file, the key path and what is valid."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from otonav.sweep._plan import plan_runs, run_id
from otonav.sweep._spec import load_sweep

pytestmark = pytest.mark.unit

SHORT = "name: short\nscene: empty\ngoal: {x: 1.0, y: 0.3}\nsim_budget: 4.0\n"


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def test_grid_times_seeds_expands_in_order_with_stable_ids(tmp_path: Path) -> None:
    _write(tmp_path / "worlds" / "a.yaml", SHORT)
    _write(tmp_path / "worlds" / "b.yaml", SHORT.replace("short", "short_b"))
    sweep = _write(
        tmp_path / "s.yaml",
        "scenarios: [acceptance, 'worlds/*.yaml']\n"
        "overrides: {nav.max_v: [0.3, 0.5], guard.stop_distance: [0.4]}\n"
        "seeds: {start: 3, count: 2}\n",
    )
    tasks = plan_runs(load_sweep(sweep), base=tmp_path)
    assert len(tasks) == 3 * 2 * 1 * 2
    assert [t.index for t in tasks] == list(range(12))
    assert [t.scenario for t in tasks[:4]] == ["acceptance"] * 4
    assert {t.scenario for t in tasks[4:8]} == {"short"}
    assert [(t.overrides, t.seed) for t in tasks[:4]] == [
        ((("nav.max_v", 0.3), ("guard.stop_distance", 0.4)), 3),
        ((("nav.max_v", 0.3), ("guard.stop_distance", 0.4)), 4),
        ((("nav.max_v", 0.5), ("guard.stop_distance", 0.4)), 3),
        ((("nav.max_v", 0.5), ("guard.stop_distance", 0.4)), 4),
    ]
    assert '"max_v":0.5' in tasks[2].stack_json
    assert '"seed":4' in tasks[1].scenario_json
    assert len({t.run_id for t in tasks}) == 12
    again = plan_runs(load_sweep(sweep), base=tmp_path)
    assert [t.run_id for t in again] == [t.run_id for t in tasks]
    assert tasks[0].run_id == run_id(tasks[0].scenario_json, 3, tasks[0].overrides)


def test_a_list_of_overrides_and_duplicates_run_once(tmp_path: Path) -> None:
    sweep = _write(
        tmp_path / "s.yaml",
        "scenarios: [empty, empty]\n"
        "overrides:\n  - {nav.max_v: 0.3, nav.kp_lin: 1.0}\n  - {nav.max_v: 0.3, nav.kp_lin: 1.0}\n"
        "  - {base.max_v: 0.6}\n",
    )
    tasks = plan_runs(load_sweep(sweep), base=tmp_path)
    assert [t.overrides for t in tasks] == [
        (("nav.max_v", 0.3), ("nav.kp_lin", 1.0)),
        (("base.max_v", 0.6),),
    ]
    assert all(t.seed == 0 and t.keep == "failures" for t in tasks)


@pytest.mark.parametrize(
    ("text", "fragments"),
    [
        ("scenarios: [acceptance]\nkeep: some\n", ("keep", "'failures', 'all' or 'none'")),
        ("scenarios: []\n", ("scenarios", "at least one")),
        ("scenario: [acceptance]\n", ("scenario", "unknown key")),
        ("scenarios: [acceptance]\nseeds: [1, -2]\n", ("seeds", "greater than or equal to 0")),
        ("scenarios: [acceptance]\nwall_ceiling_s: 0\n", ("wall_ceiling_s", "greater than 0")),
        ("scenarios: [acceptence]\n", ("scenarios.0", "'acceptence'", "acceptance, empty")),
        ("scenarios: ['nowhere/*.yaml']\n", ("scenarios.0", "matches no file")),
        ("scenarios: [missing.yaml]\n", ("missing.yaml", "no such file")),
        ("scenarios: [acceptance]\noverrides: {nav.max_vv: [1]}\n", ("nav.max_vv", "max_v")),
        ("scenarios: [acceptance]\noverrides: {nav.max_v: [-1]}\n", ("nav.max_v", "greater")),
        ("scenarios: [acceptance]\noverrides: {nav.max_v: []}\n", ("overrides.nav.max_v", "empty")),
        ("scenarios: [acceptance]\nseeds: {count: 0}\n", ("seeds", "count")),
        ("scenarios: [{generate: {seed: 1}}]\n", ("scenarios.0", "count", "required")),
        ("scenarios: [acceptance\n", ("invalid YAML", "line")),
    ],
)
def test_a_bad_sweep_file_is_one_line_and_exit_2(
    cli_fails: Callable[..., str], tmp_path: Path, text: str, fragments: tuple[str, ...]
) -> None:
    sweep = _write(tmp_path / "bad.yaml", text)
    line = cli_fails(["sweep", str(sweep), "--out", str(tmp_path / "o")], *fragments)
    assert "bad.yaml" in line
    assert not (tmp_path / "o").exists()  # nothing started


def test_a_broken_scenario_file_names_that_file(
    cli_fails: Callable[..., str], tmp_path: Path
) -> None:
    _write(tmp_path / "w" / "x.yaml", "goal: {x: fast}\n")
    sweep = _write(tmp_path / "s.yaml", "scenarios: ['w/*.yaml']\n")
    cli_fails(["sweep", str(sweep), "--out", str(tmp_path / "o")], "x.yaml", "goal.x")


@pytest.mark.parametrize(
    ("argv", "fragments"),
    [
        (["sweep"], ("sweep file", "--generate")),
        (["sweep", "--scenario", "acceptance", "--workers", "0"], ("--workers",)),
        (["sweep", "--scenario", "acceptance", "--seeds", "0"], ("--seeds",)),
        (["sweep", "--scenario", "acceptance", "--set", "nav.max_v"], ("--set", "KEY=VALUE")),
        (["sweep", "--scenario", "acceptance", "--set", "nav.nope=1"], ("nav.nope", "unknown")),
        (["sweep", "--scenario", "acceptance", "--retry-errors"], ("--retry-errors", "--resume")),
    ],
)
def test_bad_quick_form_flags(
    cli_fails: Callable[..., str], tmp_path: Path, argv: list[str], fragments: tuple[str, ...]
) -> None:
    cli_fails([*argv, "--out", str(tmp_path / "o")], *fragments)


def test_an_out_dir_holding_another_sweep_is_refused(
    cli_fails: Callable[..., str], tmp_path: Path
) -> None:
    out = tmp_path / "o"
    out.mkdir()
    (out / "results.jsonl").write_text('{"run_id": "x"}\n')
    cli_fails(["sweep", "--scenario", "empty", "--out", str(out)], "already holds", "--resume")
    (out / "sweep.json").write_text('{"fingerprint": "other"}\n')
    cli_fails(
        ["sweep", "--scenario", "empty", "--out", str(out), "--resume"],
        "different sweep",
    )
    assert (out / "results.jsonl").read_text() == '{"run_id": "x"}\n'  # nothing lost


def test_generated_worlds_are_named_by_params_and_seed_and_drawn_by_workers(
    tmp_path: Path,
) -> None:
    from otonav.scenario._generator import DENSE, generate_world
    from otonav.sweep._worlds import draw_world

    sweep = _write(
        tmp_path / "s.yaml",
        "scenarios:\n  - generate: {count: 3, seed: 10, params: {density: dense}}\n"
        "  - generate: {count: 1, params: {obstacle_count: [0, 2]}}\n"
        "overrides: {nav.max_v: [0.3, 0.5]}\n",
    )
    tasks = plan_runs(load_sweep(sweep), base=tmp_path)
    assert [(t.scenario, t.seed) for t in tasks[:6:2]] == [
        ("dense-10", 10), ("dense-11", 11), ("dense-12", 12)
    ]  # fmt: skip
    assert tasks[0].family == "generated(density=dense)"
    assert tasks[6].scenario == "sparse-0"
    assert tasks[6].family == "generated(obstacle_count=[0, 2])"
    assert all(t.scenario_json == "" and t.world is not None for t in tasks)
    assert len({t.run_id for t in tasks}) == 8
    # the worker's world is the generator's own for that seed
    assert tasks[2].world is not None
    scenario_json, labels = draw_world(*tasks[2].world)
    world = generate_world(11, DENSE)
    assert scenario_json == world.scenario.model_dump_json()
    assert labels["world_reachable"] == world.reachable
    assert labels["shortest_path_m"] == world.shortest_path_m


@pytest.mark.parametrize(
    ("params", "fragments"),
    [
        ("{density: thick}", ("scenarios.0.generate.params.density", "sparse, dense")),
        ("{obstacles: 3}", ("scenarios.0.generate.params.obstacles", "obstacle_count")),
        ("{arena: 50}", ("scenarios.0.generate.params", "arena must be in (2, 10]")),
    ],
)
def test_bad_generator_parameters(
    cli_fails: Callable[..., str], tmp_path: Path, params: str, fragments: tuple[str, ...]
) -> None:
    sweep = _write(
        tmp_path / "g.yaml", f"scenarios: [{{generate: {{count: 2, params: {params}}}}}]\n"
    )
    cli_fails(["sweep", str(sweep), "--out", str(tmp_path / "o")], "g.yaml", *fragments)


def test_the_quick_form_generates_worlds(tmp_path: Path) -> None:
    import argparse

    from otonav.cli._sweep import quick_spec

    args = argparse.Namespace(
        scenario=[], generate=4, density="dense", gen=["max_speed=0.5"], seeds=None,
        overrides=["nav.max_v=0.3,0.5"], keep="failures",
    )  # fmt: skip
    tasks = plan_runs(quick_spec(args))
    assert len(tasks) == 8
    assert tasks[0].family == "generated(density=dense,max_speed=0.5)"
    assert [t.overrides for t in tasks[:2]] == [(("nav.max_v", 0.3),), (("nav.max_v", 0.5),)]
