#!/usr/bin/env python3
# SPDX-License-Identifier: BSD-3-Clause
"""Writes a can and a cup with the same outside, and their manifest.

    scripts/can_and_cup.py OUT

OUT/can.ply is a closed cylinder of a soup can's size (66 mm x 101 mm,
meters, +z up). OUT/cup.ply has the same outer wall and bottom, a 2 mm wall
and no lid: open at the top, its inside 5 mm above its bottom.
OUT/objects.json lists them for `graspfill bench repair --objects OUT` (the
can `closed_symmetric`, the cup `open`). Only the top differs, and a grasp
that hides the top hides the difference
(docs/measurements/2026-12-07-can-or-cup.md). OUT must exist, and no file
there is overwritten.
"""
import json
import math
import os
import struct
import sys

SEGMENTS = 96  # around the axis: the facets stay 0.02 mm off the circle
RINGS = 20  # along the wall
RADIUS_M = 0.033
HEIGHT_M = 0.101
WALL_M = 0.002
INNER_BOTTOM_M = 0.005


class Mesh:
    def __init__(self):
        self.vertices = []
        self.faces = []

    def ring(self, radius, z):
        first = len(self.vertices)
        for k in range(SEGMENTS):
            t = 2.0 * math.pi * k / SEGMENTS
            self.vertices.append((radius * math.cos(t), radius * math.sin(t), z))
        return first

    def band(self, r0, z0, r1, z1, steps):
        """Rings from (r0, z0) to (r1, z1). The faces face away from the
        solid for the bands used here: up the outside, in across the rim,
        down the inside."""
        rings = [self.ring(r0 + (r1 - r0) * s / steps, z0 + (z1 - z0) * s / steps) for s in range(steps + 1)]
        for ring, following in zip(rings, rings[1:]):
            for k in range(SEGMENTS):
                a, b = ring + k, ring + (k + 1) % SEGMENTS
                c, d = following + k, following + (k + 1) % SEGMENTS
                self.faces += [(a, b, d), (a, d, c)]

    def disc(self, radius, z, up):
        centre = len(self.vertices)
        self.vertices.append((0.0, 0.0, z))
        first = self.ring(radius, z)
        for k in range(SEGMENTS):
            a, b = first + k, first + (k + 1) % SEGMENTS
            self.faces.append((centre, a, b) if up else (centre, b, a))

    def write_ply(self, path):
        with open(path, "xb") as f:
            f.write(
                (
                    "ply\nformat binary_little_endian 1.0\n"
                    f"element vertex {len(self.vertices)}\n"
                    "property float x\nproperty float y\nproperty float z\n"
                    f"element face {len(self.faces)}\n"
                    "property list uchar int vertex_indices\nend_header\n"
                ).encode("ascii")
            )
            for v in self.vertices:
                f.write(struct.pack("<3f", *v))
            for face in self.faces:
                f.write(struct.pack("<B3i", 3, *face))


def can():
    mesh = Mesh()
    mesh.disc(RADIUS_M, 0.0, up=False)
    mesh.band(RADIUS_M, 0.0, RADIUS_M, HEIGHT_M, RINGS)
    mesh.disc(RADIUS_M, HEIGHT_M, up=True)
    return mesh


def cup():
    mesh = Mesh()
    mesh.disc(RADIUS_M, 0.0, up=False)
    mesh.band(RADIUS_M, 0.0, RADIUS_M, HEIGHT_M, RINGS)
    mesh.band(RADIUS_M, HEIGHT_M, RADIUS_M - WALL_M, HEIGHT_M, 1)  # the rim
    mesh.band(RADIUS_M - WALL_M, HEIGHT_M, RADIUS_M - WALL_M, INNER_BOTTOM_M, RINGS)  # the inside
    mesh.disc(RADIUS_M - WALL_M, INNER_BOTTOM_M, up=True)
    return mesh


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__.strip())
    out = sys.argv[1]
    if not os.path.isdir(out):
        sys.exit(f"can_and_cup.py: {out} is not a folder")
    names = ("can.ply", "cup.ply", "objects.json")
    taken = [n for n in names if os.path.exists(os.path.join(out, n))]
    if taken:
        sys.exit(f"can_and_cup.py: {out} already has {', '.join(taken)}; nothing written")
    can().write_ply(os.path.join(out, "can.ply"))
    cup().write_ply(os.path.join(out, "cup.ply"))
    manifest = {
        "_about": "A can and a cup with the same outside (scripts/can_and_cup.py).",
        "objects": {
            "can": {"file": "can.ply", "kind": "closed_symmetric", "split": "tune"},
            "cup": {"file": "cup.ply", "kind": "open", "split": "tune"},
        },
    }
    with open(os.path.join(out, "objects.json"), "x") as f:
        json.dump(manifest, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
