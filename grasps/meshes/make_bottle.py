"""Write ``bottle.obj``: a 22 cm bottle of revolution, the mesh of ``grasps/bottle.yaml``.

The bundled mesh is made here, not downloaded, so that its origin and licence
are the project's own: ``python grasps/meshes/make_bottle.py`` rewrites it
(byte for byte on any machine: the coordinates are printed to 6 decimals).
A profile ``(radius, height)`` from the base to the mouth is turned about the
z axis in ``SEGMENTS`` steps and closed by a fan at each end: a watertight
surface, wound counter-clockwise seen from outside, in metres, its base on
z = 0.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

#: Steps around the axis: a multiple of 3, so that contacts 120 degrees apart lie on its edges.
SEGMENTS = 48

#: The profile, base to mouth: ``(radius, height)`` in metres (a rounded base, the body, the
#: shoulder, the neck).
PROFILE = (
    (0.030, 0.000),
    (0.034, 0.002),
    (0.035, 0.006),
    (0.035, 0.150),
    (0.033, 0.162),
    (0.027, 0.175),
    (0.019, 0.186),
    (0.014, 0.194),
    (0.013, 0.200),
    (0.013, 0.215),
    (0.014, 0.217),
    (0.014, 0.220),
)


def bottle(segments=SEGMENTS, profile=PROFILE):
    """``(vertices, faces)`` of the bottle: lists of ``(x, y, z)`` floats and of 0-based
    ``(a, b, c)`` vertex indices, counter-clockwise seen from outside."""
    vertices = [(0.0, 0.0, profile[0][1])]  # the base's centre
    for radius, height in profile:
        for k in range(segments):
            angle = 2 * math.pi * k / segments
            vertices.append((radius * math.cos(angle), radius * math.sin(angle), height))
    vertices.append((0.0, 0.0, profile[-1][1]))  # the mouth's centre (the bottle is closed)
    ring = lambda j, k: 1 + j * segments + k % segments  # noqa: E731 - the vertex k of ring j
    faces = [(0, ring(0, k + 1), ring(0, k)) for k in range(segments)]  # the base, seen from below
    for j in range(len(profile) - 1):
        for k in range(segments):
            faces.append((ring(j, k), ring(j, k + 1), ring(j + 1, k + 1)))
            faces.append((ring(j, k), ring(j + 1, k + 1), ring(j + 1, k)))
    top = len(vertices) - 1
    last = len(profile) - 1
    faces += [(top, ring(last, k), ring(last, k + 1)) for k in range(segments)]
    return vertices, faces


def obj_text(vertices, faces):
    """The Wavefront OBJ text of a mesh (1-based indices)."""
    lines = ["# bottle.obj: written by grasps/meshes/make_bottle.py (do not edit; run it again)"]
    lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    return "\n".join(lines).replace("-0.000000", "0.000000") + "\n"


if __name__ == "__main__":
    target = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).with_name("bottle.obj")
    target.write_text(obj_text(*bottle()), encoding="utf-8")
