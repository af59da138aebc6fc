"""The sweep file: which scenarios, which stack-config overrides, which seeds, what to
keep. Validated like scenario files (pydantic, strict); a mistake is a
:class:`~otonav.stack._files.ConfigFileError` naming the file and the key path.

    # sweep.yaml
    name: max-v-study
    config: ../config/stack.yaml      # optional base stack config (relative to this file)
    scenarios:
      - acceptance                    # a built-in scenario
      - worlds/*.yaml                 # a glob or a file (relative to this file)
      - generate: {count: 50, seed: 0, params: {density: dense}}
    overrides:                        # a grid (every combination) ...
      nav.max_v: [0.3, 0.4, 0.5]
    # overrides:                      # ... or a list of combinations
    #   - {nav.max_v: 0.3, nav.kp_lin: 1.0}
    seeds: [0, 1, 2]                  # or {start: 0, count: 10}; default: each scenario's own
    keep: failures                    # failures | all | none
    wall_ceiling_s: 120               # wall seconds before a run counts as hung
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Discriminator, Field, PositiveFloat, PositiveInt, Tag

Scalar = bool | int | float | str
"""A value an override may take (parsed from YAML)."""

Keep = Literal["failures", "all", "none"]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)


class GenerateSpec(_Model):
    """``count`` worlds from the seeded world generator, world seeds ``seed`` ..
    ``seed + count - 1``; ``params`` go to the generator as they are."""

    count: PositiveInt
    seed: int = Field(0, ge=0)
    params: dict[str, Scalar | tuple[Scalar, ...]] = {}
    """``density`` (a preset: sparse, dense, walled_in) and fields of the generator's
    ``WorldParams`` to replace (see ``otonav.sweep._worlds``)."""


class GenerateSource(_Model):
    generate: GenerateSpec


def _source_kind(value: object) -> str:
    return "name" if isinstance(value, str) else "generate"


ScenarioSource = Annotated[
    Annotated[str, Tag("name")] | Annotated[GenerateSource, Tag("generate")],
    Discriminator(_source_kind),
]
"""A built-in name, a file or glob, or ``{generate: {...}}``."""


class SeedRange(_Model):
    start: int = Field(0, ge=0)
    count: PositiveInt


class SweepSpec(_Model):
    """A family of runs: every scenario x every override combination x every seed."""

    name: str = "sweep"
    config: str | None = None
    """Base stack config YAML (relative to the sweep file); default: built-in defaults."""
    scenarios: tuple[ScenarioSource, ...]
    """Built-in names, scenario files, globs, or ``{generate: {...}}``."""
    overrides: dict[str, tuple[Scalar, ...]] | tuple[dict[str, Scalar], ...] = ()
    """A grid ``{key: [values]}`` (every combination) or a list of ``{key: value}``."""
    seeds: tuple[Annotated[int, Field(ge=0)], ...] | SeedRange | None = None
    """Seeds to run each scenario with; None: each scenario's own seed."""
    keep: Keep = "failures"
    """Artifacts (recording, plot, scenario file) to keep under ``runs/``."""
    wall_ceiling_s: PositiveFloat = 120.0
    """Wall seconds one run may take before its worker is killed and the run is an error."""

    def seed_list(self) -> tuple[int, ...] | None:
        if self.seeds is None:
            return None
        if isinstance(self.seeds, SeedRange):
            return tuple(range(self.seeds.start, self.seeds.start + self.seeds.count))
        return self.seeds


def load_sweep(path: Path) -> SweepSpec:
    """Read and validate a sweep file; raise ``ConfigFileError`` on any problem."""
    from otonav.stack._files import ConfigFileError, load_model

    spec = load_model(path, SweepSpec)
    if not spec.scenarios:
        raise ConfigFileError(
            f"{path}: scenarios: empty; name at least one (a built-in scenario, a file, "
            "a glob or {generate: {count: N}})"
        )
    if isinstance(spec.overrides, dict):
        for key, values in spec.overrides.items():
            if not values:
                raise ConfigFileError(
                    f"{path}: overrides.{key}: empty list; give at least one value"
                )
    return spec


def describe(spec: SweepSpec) -> dict[str, Any]:
    """The spec as plain JSON data (stored next to the results)."""
    return spec.model_dump(mode="json")
