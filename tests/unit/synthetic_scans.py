"""Synthetic worlds of line segments and an exact 2D lidar among them, for the
localization tests (no simulator: the truth is known exactly)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

Segment = tuple[float, float, float, float]


def box(cx: float, cy: float, hx: float, hy: float) -> list[Segment]:
    c = [(cx - hx, cy - hy), (cx + hx, cy - hy), (cx + hx, cy + hy), (cx - hx, cy + hy)]
    return [(*c[i], *c[(i + 1) % 4]) for i in range(4)]


def scan(
    segments: list[Segment], pose: tuple[float, float, float], beams: int = 360
) -> NDArray[np.float64]:
    """The returns (base_link, ``(N, 2)``) of a 360-degree lidar at ``pose`` among
    ``segments``: exact ray casting, 8 m range."""
    x, y, yaw = pose
    a = np.arange(beams) * 2 * math.pi / beams
    dx, dy = np.cos(a + yaw), np.sin(a + yaw)
    s = np.asarray(segments, dtype=np.float64)
    ex, ey = s[:, 2] - s[:, 0], s[:, 3] - s[:, 1]
    den = dx[:, None] * ey[None, :] - dy[:, None] * ex[None, :]
    wx, wy = s[None, :, 0] - x, s[None, :, 1] - y
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (wx * ey[None, :] - wy * ex[None, :]) / den
        u = (wx * dy[:, None] - wy * dx[:, None]) / den
    ok = (np.abs(den) > 1e-12) & (t > 0) & (u >= 0) & (u <= 1)
    r = np.where(ok, t, np.inf).min(axis=1)
    hit = r <= 8.0
    return np.stack((r[hit] * np.cos(a[hit]), r[hit] * np.sin(a[hit])), axis=1)


ROOM = box(0, 0, 5, 5) + box(1, 1, 0.4, 0.3) + box(-2, 2, 0.5, 0.5) + box(2, -2.5, 0.3, 0.8)
CORRIDOR: list[Segment] = [(-20, -1, 20, -1), (-20, 1, 20, 1)]


def circle(radius: float, sides: int = 360) -> list[Segment]:
    """A round room centred on the origin (a polygon of ``sides`` sides): a scan from
    its centre says where the robot is, but not which way it faces."""
    a = np.arange(sides + 1) * 2 * math.pi / sides
    x, y = radius * np.cos(a), radius * np.sin(a)
    return [(x[i], y[i], x[i + 1], y[i + 1]) for i in range(sides)]
