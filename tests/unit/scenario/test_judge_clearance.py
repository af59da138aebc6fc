"""The judge's minimum clearance skips boxes that cannot be the closest; the figure (and
where it happened) must be exactly what checking every box at every sample gives."""

from __future__ import annotations

import math
import random

import pytest

from otonav.hal import BoxObstacle, FakeHardware, GroundTruth
from otonav.scenario import Judge

pytestmark = pytest.mark.unit


class _World(FakeHardware):
    def __init__(self, boxes: tuple[BoxObstacle, ...]) -> None:
        super().__init__()
        self.boxes = boxes
        self.truth = GroundTruth(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)

    def obstacles(self) -> tuple[BoxObstacle, ...]:
        return self.boxes

    def walls(self) -> tuple[BoxObstacle, ...]:
        return ()

    def ground_truth(self) -> GroundTruth:
        return self.truth


@pytest.mark.parametrize("seed", range(8))
def test_min_clearance_equals_checking_every_box_every_sample(seed: int) -> None:
    rng = random.Random(seed)
    boxes = tuple(
        BoxObstacle(
            rng.uniform(-4, 4),
            rng.uniform(-4, 4),
            rng.uniform(0.05, 1.0),
            rng.uniform(0.05, 1.0),
            rng.uniform(-math.pi, math.pi),
        )
        for _ in range(rng.randint(1, 12))
    )
    world = _World(boxes)
    judge = Judge(world, (10.0, 10.0), 0.1)
    x = y = 0.0
    best, best_at = math.inf, (math.nan, math.nan)
    for k in range(3000):
        # Mostly small steps (a robot at 100 Hz), now and then a jump (a teleport).
        step = 0.004 if rng.random() < 0.99 else 2.0
        x += rng.uniform(-step, step)
        y += rng.uniform(-step, step)
        world.truth = GroundTruth(x, y, 0.0, 0.0, 0.0, 0.0, 0.0)
        judge.sample(k * 0.01)
        for box in boxes:
            d = box.distance_to(x, y)
            if d < best:
                best, best_at = d, (x, y)
        assert judge.min_clearance == best
        assert judge.min_clearance_at == best_at
