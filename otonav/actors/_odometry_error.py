"""A deterministic odometry error model for simulation: the drift a real robot's
odometry has (a wheel radius a little off, a gyro with a bias and noise), so that
localization has something to correct (``world.odometry_error``; off by default)."""

from __future__ import annotations

import numpy as np


class OdometryError:
    """Applied by the bridge to each odometry sample: the distance the wheels report
    is scaled by ``1 + scale`` and the yaw rate gets ``gyro_bias`` plus white noise of
    standard deviation ``gyro_noise`` (rad/s) from a generator seeded with ``seed``:
    the same run drifts the same way every time."""

    def __init__(
        self, *, scale: float = 0.0, gyro_bias: float = 0.0, gyro_noise: float = 0.0, seed: int = 0
    ) -> None:
        if gyro_noise < 0.0:
            raise ValueError(f"gyro_noise must be >= 0 rad/s, got {gyro_noise}")
        self.scale = scale
        self.gyro_bias = gyro_bias
        self.gyro_noise = gyro_noise
        self._rng = np.random.default_rng(seed)

    def apply(self, distance: float, gyro_z: float) -> tuple[float, float]:
        """(distance m, yaw rate rad/s) as the mis-calibrated odometry sees them."""
        rate = gyro_z + self.gyro_bias
        if self.gyro_noise > 0.0:
            rate += self.gyro_noise * float(self._rng.standard_normal())
        return distance * (1.0 + self.scale), rate
