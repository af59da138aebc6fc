"""What otonav.nav._dwa documents at its edges (issue 24, ADR 0060 round three):

* the defaults of ``DwaParams`` are the ones the launch file ``config/stack.yaml``
  documents (its header: "Every key is optional: the defaults live in
  otonav/stack/_config.py", whose ``nav.dwa`` section takes them from ``DwaParams``; the
  config reference in docs/ is generated from there too). Read from the YAML text, not
  copied: the file is what a user reads;
* "admissible when ``v * latency + v**2 / (2 * max_accel) <= free length``": a sample
  that stops exactly at its free length is admissible (the tie built from exact floats);
* the fast path's arc is the command when every pose has a clearance of *at least*
  ``radius + fast_margin + v * dt / 2``: exactly that much is enough.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from otonav.nav._dwa import DwaParams, clear_arc, dwa_step

pytestmark = pytest.mark.unit

_STACK = Path(__file__).resolve().parents[2] / "config" / "stack.yaml"


def _launch_file() -> dict[str, Any]:
    loaded: dict[str, Any] = yaml.safe_load(_STACK.read_text(encoding="utf-8"))
    return loaded


def test_the_defaults_are_the_ones_the_launch_file_documents() -> None:
    doc = _launch_file()
    nav, base = doc["nav"], doc["base"]
    want = dict(nav["dwa"])  # horizon, dt, samples, latency, cap, weights, fast path
    want["max_v"] = nav["max_v"]
    want["max_omega"] = nav["max_omega"]
    want["rotate_threshold"] = nav["turn_in_place_threshold"]
    want["max_accel"] = base["max_accel"]  # "the base's" (DwaParams' docstring)
    want["max_alpha"] = base["max_alpha"]
    want["period"] = 1.0 / nav["rate_hz"]  # one navigator step
    got = DwaParams()
    assert {k: getattr(got, k) for k in want} == pytest.approx(want, rel=1e-12)
    assert {type(getattr(got, k)) for k in ("v_samples", "omega_samples")} == {int}
    assert got.fast_path is True


def test_a_sample_that_stops_exactly_at_its_free_length_is_admissible() -> None:
    """Straight ahead at v = 0.5 (the window's only speed: the target is behind), poses
    every 0.125 m; the clearance 1 - x drops under the radius 0.7 first at the fourth
    pose (x = 0.375), so the free length is v * t[2] = 0.25 m, and the stop, 0.5^2 /
    (2 * 0.5) with no latency, is 0.25 m too: both samples are admissible."""
    p = DwaParams(
        max_v=1.0,
        max_accel=0.5,
        period=0.5,
        horizon=1.0,
        dt=0.25,
        v_samples=3,
        omega_samples=1,
        radius=0.7,
        latency=0.0,
        rotate_threshold=0.6,
        fast_path=False,
    )

    def field(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return 1.0 - x

    r = dwa_step((0.0, 0.0, 0.0), 0.75, 0.0, (-5.0, 0.0), 5.0, field, p)
    assert (r.v, r.samples, r.admissible) == (0.5, 2, 2)
    # a hair longer stop (1 us of latency) and neither fits: braking
    late = dataclasses.replace(p, latency=1e-6)
    r = dwa_step((0.0, 0.0, 0.0), 0.75, 0.0, (-5.0, 0.0), 5.0, field, late)
    assert (r.admissible, r.reason) == (0, "no admissible trajectory: braking")


def test_the_fast_path_takes_an_arc_whose_clearance_is_exactly_the_bound() -> None:
    """radius + fast_margin + v * dt / 2 = 0.25 + 0.25 + 0.5 * 0.25 / 2 = 0.5625 (exact
    in binary) everywhere: the arc is the command; a hair less and it is not."""
    p = DwaParams(max_v=1.0, max_accel=0.5, period=0.5, dt=0.25, radius=0.25, fast_margin=0.25)
    arc = clear_arc((0.0, 0.0, 0.0), 0.25, 0.0, (3.0, 0.0), 3.0, lambda x, y: 0.5625, p)
    assert arc is not None
    assert (arc.v, arc.omega, arc.clearance, arc.reason) == (0.5, 0.0, 0.5625, "clear arc")
    assert clear_arc((0.0, 0.0, 0.0), 0.25, 0.0, (3.0, 0.0), 3.0, lambda x, y: 0.5624, p) is None
