"""Footprint and clearance: the one radius every collision and clearance check uses.

The judged point is base_link's origin, the midpoint of the wheel axle (the scenario
judge measures the robot centre's distance to every obstacle surface, and that centre
is ground truth's x, y: the chassis body origin). A diff-drive robot spinning in place
turns about that same point, so the footprint sweeps a circle of radius
``footprint_radius`` (the farthest footprint corner from base_link) around it.

Every check in ``otonav.nav`` is therefore a check on the centre: it must stay at
least :func:`centre_clearance` from every scan return, which is the larger of

* the configured clearance (what the judge demands, plus a margin), and
* the footprint radius plus a padding (so the body itself never touches a return,
  whatever the heading; this term wins for a robot larger than the clearance).

For the shipped robot the footprint radius is 0.243 m (corner (0.21, 0.1225) m of the
MJCF's bounding rectangle), under the 0.3 m clearance: the clearance binds.
"""

from __future__ import annotations

import math

__all__ = ("centre_clearance",)


def centre_clearance(clearance: float, footprint_radius: float, padding: float) -> float:
    """Smallest allowed distance, m, from the robot centre (base_link) to any return:
    ``max(clearance, footprint_radius + padding)``, each m and >= 0 (ValueError naming
    the argument otherwise)."""
    for name, value in (
        ("clearance", clearance),
        ("footprint_radius", footprint_radius),
        ("padding", padding),
    ):
        if not (math.isfinite(value) and value >= 0.0):
            raise ValueError(f"{name} must be finite and >= 0 m, got {value!r}")
    return max(clearance, footprint_radius + padding)
