"""A quick start: the CLI imports what a command uses and nothing else.

``--help``, ``scenarios`` and ``info`` must not load the simulator, the plotting library or
GLFW (they took 1.0-1.4 s when the CLI imported everything eagerly); a headless ``run``
never loads GLFW. Each check runs in a fresh interpreter and reads its ``sys.modules``
(the only honest view: this test process has imported everything already).
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

pytestmark = pytest.mark.unit

HEAVY = ("matplotlib", "glfw", "mujoco", "numpy", "anyio")
"""Never imported to parse arguments, print help, list scenarios or summarize a file."""


def _loaded_after(code: str) -> set[str]:
    """The top-level packages in ``sys.modules`` after running ``code`` in a child."""
    script = textwrap.dedent(code) + textwrap.dedent(
        """
        import json as _json, sys as _sys
        print("MODULES", _json.dumps(sorted({m.split(".")[0] for m in _sys.modules})))
        """
    )
    child = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=60, check=False
    )
    assert child.returncode == 0, child.stderr
    (line,) = [x for x in child.stdout.splitlines() if x.startswith("MODULES ")]
    return set(json.loads(line.removeprefix("MODULES ")))


def test_importing_the_cli_and_building_its_parser_loads_nothing_heavy() -> None:
    loaded = _loaded_after("import otonav.cli\notonav.cli.build_parser()\n")
    assert not loaded & set(HEAVY), f"import otonav.cli pulled in {sorted(loaded & set(HEAVY))}"


@pytest.mark.parametrize("argv", [["--help"], ["run", "--help"], ["scenarios"]])
def test_help_and_scenarios_load_nothing_heavy(argv: list[str]) -> None:
    loaded = _loaded_after(
        f"""
        import contextlib, io
        from otonav.cli import main
        with contextlib.redirect_stdout(io.StringIO()):
            try:
                code = main({argv!r})
            except SystemExit as exc:  # argparse's --help
                code = exc.code
        assert code == 0, code
        """
    )
    assert not loaded & set(HEAVY), f"otonav {argv} pulled in {sorted(loaded & set(HEAVY))}"


def test_info_loads_nothing_heavy(tmp_path: Path) -> None:
    from otonav.msgs import Clock, Time
    from otonav.record._writer import RecordingWriter

    recording = tmp_path / "r.mcap"
    writer = RecordingWriter(recording)
    writer.write("/clock", Clock(clock=Time.from_seconds(0.5)), 0.5)
    writer.finish()
    loaded = _loaded_after(
        f"""
        import contextlib, io
        from otonav.cli import main
        with contextlib.redirect_stdout(io.StringIO()):
            assert main(["info", {str(recording)!r}]) == 0
        """
    )
    assert not loaded & set(HEAVY), f"otonav info pulled in {sorted(loaded & set(HEAVY))}"


def test_a_headless_run_loads_no_glfw_and_no_matplotlib_before_it_plots(tmp_path: Path) -> None:
    scenario = tmp_path / "short.yaml"
    scenario.write_text("name: short\nscene: empty\ngoal: {x: 3.0, y: 0.0}\nsim_budget: 0.2\n")
    loaded = _loaded_after(
        f"""
        import contextlib, io, sys, traceback
        from otonav.cli import main

        first_import = []

        class Watch:  # records who imports matplotlib first; finds nothing itself
            def find_spec(self, name, path=None, target=None):
                if name == "matplotlib" and not first_import:
                    first_import.append([f.name for f in traceback.extract_stack()])
                return None

        assert "matplotlib" not in sys.modules, "importing the CLI loaded matplotlib"
        sys.meta_path.insert(0, Watch())
        with contextlib.redirect_stdout(io.StringIO()):
            code = main(["run", "--scenario", {str(scenario)!r}, "--out", {str(tmp_path)!r}])
        assert code == 1, code  # 0.2 s of budget: not reached
        assert first_import, "no plot was drawn"
        assert "plot_trajectory" in first_import[0], (
            f"matplotlib was imported before a plot was drawn, by: {{first_import[0]}}"
        )
        """
    )
    assert "glfw" not in loaded, "a headless run loaded GLFW"
