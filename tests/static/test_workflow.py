"""Layer 0: delivery that cannot run here is kept honest by reading it.

The CI workflow (.github/workflows/ci.yml) runs on a forge, never on these machines: these
tests parse it and hold it to what docs/adr/0049 promises (the merge-queue trigger, the
CPython matrix that pyproject.toml and `make test-versions` also state, `make test` as the
command). The Containerfile is built by `make test-image`, which is slow; its promises
that a quick read can check are checked here. The linters the static layer runs on both
(actionlint, hadolint) are shown to reject a broken file, so their green means something.
"""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib
from pathlib import Path
from typing import Any

import yaml

ROOT = Path(__file__).resolve().parents[2]
WORKFLOW = ROOT / ".github" / "workflows" / "ci.yml"
CONTAINERFILE = ROOT / "Containerfile"
BIN = Path(sys.executable).parent


def _workflow() -> dict[Any, Any]:
    loaded = yaml.safe_load(WORKFLOW.read_text())
    assert isinstance(loaded, dict)
    return loaded


def _triggers(workflow: dict[Any, Any]) -> dict[str, Any]:
    # YAML 1.1 reads the bare key `on` as the boolean True
    triggers = workflow.get("on", workflow.get(True))
    assert isinstance(triggers, dict), f"`on:` must be a mapping, got {triggers!r}"
    return triggers


def _pyproject() -> dict[str, Any]:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]  # type: ignore[no-any-return]


def _classifier_versions() -> list[str]:
    prefix = "Programming Language :: Python :: "
    found = [c.removeprefix(prefix) for c in _pyproject()["classifiers"] if c.startswith(prefix)]
    return [v for v in found if re.fullmatch(r"3\.\d+", v)]


def _steps_running(job: dict[str, Any]) -> list[str]:
    return [str(step["run"]) for step in job["steps"] if "run" in step]


def test_the_gate_runs_on_pull_requests_and_in_the_merge_queue() -> None:
    triggers = _triggers(_workflow())
    assert "pull_request" in triggers
    assert "merge_group" in triggers, "a merge queue can only require checks that run on it"


def test_the_matrix_is_every_supported_cpython_and_pyproject_says_the_same() -> None:
    gate = _workflow()["jobs"]["gate"]
    matrix = gate["strategy"]["matrix"]["python"]
    assert matrix == ["3.11", "3.12", "3.13", "3.14"]
    assert _classifier_versions() == matrix, "pyproject classifiers and the CI matrix differ"
    assert _pyproject()["requires-python"] == f">={matrix[0]}"
    assert gate["strategy"]["fail-fast"] is False, "one version's failure must not hide another's"


def test_test_versions_starts_where_requires_python_does() -> None:
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        import test_versions
    finally:
        sys.path.remove(str(ROOT / "scripts"))
    minimum = ".".join(map(str, test_versions.MINIMUM))
    assert _pyproject()["requires-python"] == f">={minimum}"


def test_each_gate_job_runs_what_a_developer_runs_with_a_pip_cache() -> None:
    gate = _workflow()["jobs"]["gate"]
    commands = _steps_running(gate)
    assert any(c.split()[:2] == ["make", "test"] for c in commands), commands
    setup = [s for s in gate["steps"] if str(s.get("uses", "")).startswith("actions/setup-python")]
    assert len(setup) == 1
    assert setup[0]["with"]["python-version"] == "${{ matrix.python }}"
    assert setup[0]["with"]["cache"] == "pip"
    assert "constraints.txt" in setup[0]["with"]["cache-dependency-path"]


def test_the_image_is_built_on_main_from_the_containerfile() -> None:
    image = _workflow()["jobs"]["image"]
    assert "refs/heads/main" in image["if"]
    assert image["needs"] == "gate"
    commands = "\n".join(_steps_running(image))
    assert "podman build -f Containerfile" in commands
    assert "--scenario acceptance" in commands
    assert _triggers(_workflow())["push"]["branches"] == ["main"]


def _stages(text: str) -> list[list[str]]:
    """The Containerfile's instructions (continuation lines joined), split into stages."""
    joined = re.sub(r"\\\n", " ", text)
    lines = [ln.strip() for ln in joined.splitlines() if ln.strip() and not ln.startswith("#")]
    stages: list[list[str]] = [[]]
    for line in lines:
        if line.upper().startswith("FROM "):
            stages.append([])
        stages[-1].append(line)
    return stages


def test_the_containerfile_is_multi_stage_on_a_python_slim_base_and_runs_as_non_root() -> None:
    preamble, *stages = _stages(CONTAINERFILE.read_text())
    assert len(stages) == 2, "a build stage and a runtime stage"
    assert "ARG BASE_IMAGE=docker.io/library/python:3.11-slim-bookworm" in preamble
    assert all(stage[0].startswith("FROM ${BASE_IMAGE} AS ") for stage in stages)
    runtime = stages[-1]
    assert any(line.startswith("COPY --from=build /opt/venv /opt/venv") for line in runtime)
    users = [line.split()[1] for line in runtime if line.startswith("USER ")]
    assert users, "the runtime stage must set a user"
    assert users[-1].split(":")[0] not in ("0", "root")


def test_the_entrypoint_execs_otonav_so_signals_reach_it() -> None:
    *_, runtime = _stages(CONTAINERFILE.read_text())
    (entrypoint,) = [line for line in runtime if line.startswith("ENTRYPOINT ")]
    assert entrypoint.startswith('ENTRYPOINT ["'), "exec form: no extra shell around it"
    assert '&& exec otonav \\"$@\\"' in entrypoint, entrypoint


def _lint(argv: list[str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, timeout=60, check=False)


def test_actionlint_rejects_a_broken_workflow(tmp_path: Path) -> None:
    broken = WORKFLOW.read_text().replace("${{ matrix.python }}", "${{ matrix.pyhton }}")
    assert broken != WORKFLOW.read_text()
    (tmp_path / "ci.yml").write_text(broken)
    done = _lint([str(BIN / "actionlint"), "-shellcheck=", str(tmp_path / "ci.yml")])
    assert done.returncode == 1, done.stdout + done.stderr
    assert "pyhton" in done.stdout


def test_hadolint_rejects_a_containerfile_that_runs_as_root(tmp_path: Path) -> None:
    broken = CONTAINERFILE.read_text() + "\nUSER root\n"
    (tmp_path / "Containerfile").write_text(broken)
    done = _lint([str(BIN / "hadolint"), str(tmp_path / "Containerfile")])
    assert done.returncode == 1, done.stdout + done.stderr
    assert "DL3002" in done.stdout, done.stdout
