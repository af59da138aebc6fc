"""A sweep file expanded into runs: every scenario x every override combination x every
seed, each a self-contained :class:`RunTask` (plain data, picklable, JSON inside) that
any worker on any machine can execute. The expansion is deterministic, and a run's id
is a hash of what it runs, so a resumed sweep finds its finished runs again."""

from __future__ import annotations

import glob
import hashlib
import itertools
import json
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

from pydantic import ValidationError

from otonav import limits
from otonav.scenario import ScenarioConfig
from otonav.scenario._builtin import BUILTIN
from otonav.stack import StackConfig
from otonav.stack._files import ConfigFileError, describe_validation_error, load_model
from otonav.stack._launch import add_actors, check_actors
from otonav.stack._loading import load_stack_file
from otonav.stack._overrides import apply_overrides
from otonav.sweep._spec import GenerateSource, Keep, Scalar, SeedRange, SweepSpec
from otonav.sweep._worlds import world_name, world_params_json

Override = tuple[str, Scalar]


@dataclass(frozen=True, slots=True)
class RunTask:
    """One run: what to simulate, with which config, and what to keep."""

    run_id: str
    """Stable hash of (scenario, seed, overrides): the key results are resumed by."""
    index: int
    """Position in the sweep's order (reports sort by it)."""
    scenario: str
    """The scenario's name."""
    family: str
    """What reports group by: the scenario name, or ``generated`` and its parameters."""
    source: str | None
    """How ``otonav run --scenario`` names it (a built-in name or a file path); None
    for a generated world (its repro uses the kept ``scenario.yaml``)."""
    seed: int
    overrides: tuple[Override, ...]
    scenario_json: str
    """The scenario to run; empty for a generated world (the worker draws it)."""
    stack_json: str
    keep: Keep
    wall_ceiling_s: float
    config: str | None = None
    """The base stack config file, for the repro command."""
    world: tuple[str, int] | None = None
    """A generated world: (generator parameters as JSON, world seed)."""
    actors: tuple[str, ...] = ()
    """The nodes ``--actor`` launched in every run (``module:Class``), for the repro."""

    @property
    def label(self) -> str:
        sets = " ".join(f"{k}={format_value(v)}" for k, v in self.overrides)
        return f"{self.scenario} seed={self.seed}" + (f" {sets}" if sets else "")


def format_value(value: Scalar) -> str:
    """An override value as ``--set`` takes it (a YAML scalar)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


@dataclass(frozen=True, slots=True)
class _Scenario:
    config: ScenarioConfig | None
    """None for a generated world (drawn by the worker)."""
    family: str
    source: str | None
    world: tuple[str, int] | None = None

    @property
    def name(self) -> str:
        if self.config is not None:
            return self.config.name
        assert self.world is not None
        return world_name(*self.world)

    @property
    def seed(self) -> int:
        if self.config is not None:
            return self.config.seed
        assert self.world is not None
        return self.world[1]


def _display(path: Path) -> str:
    """A path as the user would type it from here (relative when under the cwd)."""
    absolute = path.resolve()
    try:
        return str(absolute.relative_to(Path.cwd()))
    except ValueError:
        return str(absolute)


def _resolve_scenarios(spec: SweepSpec, base: Path, where: str) -> list[_Scenario]:
    found: list[_Scenario] = []
    for i, entry in enumerate(spec.scenarios):
        key = f"{where}: scenarios.{i}"
        if isinstance(entry, GenerateSource):
            gen = entry.generate
            params_json = world_params_json(gen, key)
            label = ",".join(
                f"{k}={format_value(v) if not isinstance(v, tuple) else list(v)}"
                for k, v in sorted(gen.params.items())
            )
            family = f"generated({label})" if label else "generated"
            found += [
                _Scenario(None, family, None, (params_json, world_seed))
                for world_seed in range(gen.seed, gen.seed + gen.count)
            ]
        elif entry in BUILTIN:
            found.append(_Scenario(BUILTIN[entry], entry, entry))
        elif any(c in entry for c in "*?["):
            matches = sorted(glob.glob(str(base / entry), recursive=True))
            if not matches:
                raise ConfigFileError(f"{key}: the glob {entry!r} matches no file (under {base})")
            for m in matches:
                s = load_model(Path(m), ScenarioConfig)
                found.append(_Scenario(s, s.name, _display(Path(m))))
        else:
            path = base / entry
            if not path.exists():
                what = "no such file" if path.suffix in (".yaml", ".yml") else "not"
                raise ConfigFileError(
                    f"{key}: {entry!r}: {what} (valid: a built-in scenario "
                    f"({', '.join(BUILTIN)}), a scenario file or a glob, relative to {base})"
                )
            s = load_model(path, ScenarioConfig)
            found.append(_Scenario(s, s.name, _display(path)))
    return found


def override_combinations(spec: SweepSpec) -> list[tuple[Override, ...]]:
    """The grid's every combination (keys in file order), or the list as given."""
    if isinstance(spec.overrides, dict):
        keys = list(spec.overrides)
        return [
            tuple(zip(keys, values, strict=True))
            for values in itertools.product(*(spec.overrides[k] for k in keys))
        ]
    return [tuple(combo.items()) for combo in spec.overrides] or [()]


def _with_seed(scenario: ScenarioConfig, seed: int, where: str) -> ScenarioConfig:
    if seed == scenario.seed:
        return scenario
    try:
        return ScenarioConfig.model_validate({**scenario.model_dump(), "seed": seed})
    except ValidationError as exc:
        raise ConfigFileError(describe_validation_error(f"{where}: seeds", exc)) from None


def run_id(
    scenario_json: str,
    seed: int,
    overrides: Sequence[Override],
    world: tuple[str, int] | None = None,
) -> str:
    what: object = scenario_json if world is None else ["generate", *world]
    key = json.dumps([what, seed, [list(o) for o in overrides]], sort_keys=True)
    return hashlib.sha256(key.encode()).hexdigest()[:12]


def plan_runs(
    spec: SweepSpec,
    *,
    base: Path = Path("."),
    where: str = "sweep",
    actors: Sequence[str] = (),
) -> list[RunTask]:
    """Every run of ``spec``, in order, each once. ``base``: where relative paths in the
    spec start (the sweep file's directory); ``where`` names the file in errors. A plan
    of more than :data:`~otonav.limits.MAX_SWEEP_RUNS` runs is refused (counted before
    it is expanded). ``actors``: ``module:Class`` nodes launched in every run
    (``--actor``)."""
    check_plan_size(spec, base, where)
    return list(_iter_runs(spec, base, where, actors))


def check_plan_size(spec: SweepSpec, base: Path, where: str) -> int:
    """The plan's size before expansion, an upper bound (duplicates are dropped later):
    raise ``ConfigFileError`` when it is over :data:`~otonav.limits.MAX_SWEEP_RUNS`."""
    scenarios = 0
    for entry in spec.scenarios:
        if isinstance(entry, GenerateSource):
            scenarios += entry.generate.count
        elif entry not in BUILTIN and any(c in entry for c in "*?["):
            scenarios += max(1, len(glob.glob(str(base / entry), recursive=True)))
        else:
            scenarios += 1
    if isinstance(spec.overrides, dict):
        combos = math.prod(len(values) for values in spec.overrides.values())
    else:
        combos = max(1, len(spec.overrides))
    if spec.seeds is None:
        seeds = 1
    elif isinstance(spec.seeds, SeedRange):
        seeds = spec.seeds.count
    else:
        seeds = len(spec.seeds)
    total = scenarios * combos * seeds
    if total > limits.MAX_SWEEP_RUNS:
        raise ConfigFileError(
            f"{where}: the plan has {total:,} runs (scenarios x override combinations x "
            f"seeds = {scenarios:,} x {combos:,} x {seeds:,}), more than "
            f"{limits.MAX_SWEEP_RUNS:,} (otonav.limits.MAX_SWEEP_RUNS); split it into "
            "smaller sweeps"
        )
    return total


def _iter_runs(spec: SweepSpec, base: Path, where: str, actors: Sequence[str]) -> Iterator[RunTask]:
    config_path = str(base / spec.config) if spec.config is not None else None
    stack = StackConfig()
    if config_path:
        stack = load_stack_file(config_path)
    configured = len(stack.actors)
    if actors:
        stack = add_actors(stack, actors)
    launched = tuple(entry.class_ or "" for entry in stack.actors[configured:])
    scenarios = _resolve_scenarios(spec, base, where)
    combos = override_combinations(spec)
    overridden = [
        apply_overrides(
            stack,
            [f"{k}={format_value(v)}" for k, v in combo],
            source=f"{where}: overrides",
        )
        for combo in combos
    ]
    for each in overridden:  # every launched node importable, its parameters valid
        check_actors(each.actors)
    stacks = [each.model_dump_json() for each in overridden]
    seeds = spec.seed_list()
    seen: set[str] = set()
    index = 0
    for sc in scenarios:
        for combo, stack_json in zip(combos, stacks, strict=True):
            for seed in seeds if seeds is not None else (sc.seed,):
                scenario_json = (
                    _with_seed(sc.config, seed, where).model_dump_json() if sc.config else ""
                )
                rid = run_id(scenario_json, seed, combo, sc.world)
                if rid in seen:  # the same run twice: a deterministic sim gives the same answer
                    continue
                seen.add(rid)
                yield RunTask(
                    run_id=rid,
                    index=index,
                    scenario=sc.name,
                    family=sc.family,
                    source=sc.source,
                    seed=seed,
                    overrides=combo,
                    scenario_json=scenario_json,
                    stack_json=stack_json,
                    keep=spec.keep,
                    wall_ceiling_s=spec.wall_ceiling_s,
                    config=_display(Path(config_path)) if config_path else None,
                    world=sc.world,
                    actors=launched,
                )
                index += 1
