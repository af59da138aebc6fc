"""Writes the mesh files of the test robot ``pathfinder`` (run once; the files are
committed). Meshes as CAD exports give them: millimetres, the wheel's axle along the
mesh's z, an octagonal chassis; OBJ for the MJCF, binary STL for the URDF."""

from __future__ import annotations

import math
import struct
from pathlib import Path

HERE = Path(__file__).parent / "meshes"


Verts = list[tuple[float, float, float]]
Tris = list[tuple[int, int, int]]


def prism(radius: float, half_height: float, sides: int) -> tuple[Verts, Tris]:
    """A right prism about z: vertices (mm) and triangles (0-based)."""
    verts: Verts = [(0.0, 0.0, -half_height), (0.0, 0.0, half_height)]
    for i in range(sides):
        a = 2 * math.pi * i / sides
        x, y = radius * math.cos(a), radius * math.sin(a)
        verts += [(x, y, -half_height), (x, y, half_height)]
    tris: Tris = []
    for i in range(sides):
        lo, hi = 2 + 2 * i, 3 + 2 * i
        nlo, nhi = 2 + 2 * ((i + 1) % sides), 3 + 2 * ((i + 1) % sides)
        tris += [(0, nlo, lo), (1, hi, nhi), (lo, nlo, nhi), (lo, nhi, hi)]
    return verts, tris


def write_obj(path: Path, verts: Verts, tris: Tris) -> None:
    lines = [f"v {x:.3f} {y:.3f} {z:.3f}" for x, y, z in verts]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in tris]
    path.write_text("\n".join(lines) + "\n")


def write_stl(path: Path, verts: Verts, tris: Tris) -> None:
    data = bytearray(b"pathfinder test mesh".ljust(80, b" "))
    data += struct.pack("<I", len(tris))
    for tri in tris:
        data += struct.pack("<3f", 0.0, 0.0, 0.0)
        for index in tri:
            data += struct.pack("<3f", *verts[index])
        data += struct.pack("<H", 0)
    path.write_bytes(bytes(data))


if __name__ == "__main__":
    HERE.mkdir(parents=True, exist_ok=True)
    wheel = prism(76.2, 12.5, 32)  # a 3-inch wheel, 25 mm wide
    chassis = prism(170.0, 50.0, 8)  # octagonal deck, 100 mm high
    write_obj(HERE / "wheel.obj", *wheel)
    write_obj(HERE / "chassis.obj", *chassis)
    write_stl(HERE / "wheel.stl", *wheel)
    write_stl(HERE / "chassis.stl", *chassis)
