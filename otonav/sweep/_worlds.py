"""Generated worlds in a sweep: ``{generate: {count, seed, params}}`` names worlds by
(parameters, world seed); workers draw them (``otonav.scenario._generator``: ~30 ms a
sparse world, ~90 ms a dense one here, so 1,000 of them drawn by the driver alone would
hold the sweep up for a minute and more).

``params``: ``density`` picks a preset (``sparse``, ``dense``, ``walled_in``; default
``sparse``) and any other key replaces that field of
:class:`~otonav.scenario._generator.WorldParams` (ranges as two-item lists), e.g.
``{density: dense, obstacle_count: [20, 24], max_speed: 0.5}``.
"""

from __future__ import annotations

import dataclasses
import json
from typing import Any

from otonav.stack._files import ConfigFileError
from otonav.sweep._spec import GenerateSpec


def world_params_json(spec: GenerateSpec, where: str) -> str:
    """The generator parameters ``spec`` names, checked, as canonical JSON."""
    from otonav.scenario._generator import PRESETS, WorldParams

    params = dict(spec.params)
    density = params.pop("density", "sparse")
    if density not in PRESETS:
        raise ConfigFileError(
            f"{where}.generate.params.density: {density!r} is not a preset "
            f"(valid: {', '.join(PRESETS)})"
        )
    fields = {f.name for f in dataclasses.fields(WorldParams)}
    unknown = sorted(set(params) - fields)
    if unknown:
        raise ConfigFileError(
            f"{where}.generate.params.{unknown[0]}: unknown generator parameter "
            f"(valid: density, {', '.join(sorted(fields))})"
        )
    values: dict[str, Any] = {
        k: tuple(v) if isinstance(v, list | tuple) else v for k, v in params.items()
    }
    try:
        world = dataclasses.replace(PRESETS[str(density)], **values)
    except (ValueError, TypeError) as exc:
        raise ConfigFileError(f"{where}.generate.params: {exc}") from None
    return json.dumps(dataclasses.asdict(world), sort_keys=True)


def world_name(params_json: str, seed: int) -> str:
    """The generated scenario's name, known without drawing the world."""
    return f"{json.loads(params_json)['name']}-{seed}"


def draw_world(params_json: str, seed: int) -> tuple[str, dict[str, Any]]:
    """(the scenario as JSON, the world's labels) for world ``seed``."""
    from otonav.scenario._generator import WorldParams, generate_world

    raw: dict[str, Any] = json.loads(params_json)
    fields: dict[str, Any] = {k: tuple(v) if isinstance(v, list) else v for k, v in raw.items()}
    params = WorldParams(**fields)
    world = generate_world(seed, params)
    labels = {
        "world_seed": seed,
        "world_reachable": world.reachable,
        "shortest_path_m": world.shortest_path_m,
        "optimal_time_s": world.optimal_time_s,
    }
    return world.scenario.model_dump_json(), labels
