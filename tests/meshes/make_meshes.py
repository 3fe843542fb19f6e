"""The meshes of the solid's tests (issue 35), as users get them: open, overlapping, in pieces, hollow, apart.

Each is an OBJ of boxes and prisms written here with numpy alone; ``EXPECTED`` gives the solid each
bounds (its volume and centre of mass, exact: the winding number's solid), which the tests hold ours
to.  Lengths in metres but ``cube_mm.stl``'s (a 65 mm cube in millimetres, ASCII STL).

Run: ``python tests/meshes/make_meshes.py`` (writes beside itself).
"""

from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
SEGMENTS = 64


def box(lo, hi):
    """A box from corner ``lo`` to ``hi``: 8 vertices, 12 faces wound outwards."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    v = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    f = [
        [0, 1, 3],
        [0, 3, 2],
        [4, 6, 7],
        [4, 7, 5],
        [0, 4, 5],
        [0, 5, 1],
        [2, 3, 7],
        [2, 7, 6],
        [0, 2, 6],
        [0, 6, 4],
        [1, 5, 7],
        [1, 7, 3],
    ]
    return v, np.array(f)


def cylinder(radius, height, top=True):
    """A prism of ``SEGMENTS`` sides round the z axis from 0 to ``height``; ``top=False`` leaves its top open."""
    t = 2 * np.pi * np.arange(SEGMENTS) / SEGMENTS
    ring = np.stack([radius * np.cos(t), radius * np.sin(t)], axis=1)
    v = np.concatenate(
        [np.c_[ring, np.zeros(SEGMENTS)], np.c_[ring, np.full(SEGMENTS, height)], [[0, 0, 0], [0, 0, height]]]
    )
    i = np.arange(SEGMENTS)
    j = (i + 1) % SEGMENTS
    f = [
        np.stack([i, j, j + SEGMENTS], 1),
        np.stack([i, j + SEGMENTS, i + SEGMENTS], 1),
        np.stack([j, i, np.full(SEGMENTS, 2 * SEGMENTS)], 1),
    ]
    if top:
        f.append(np.stack([i + SEGMENTS, j + SEGMENTS, np.full(SEGMENTS, 2 * SEGMENTS + 1)], 1))
    return v, np.concatenate(f)


def join(*parts):
    vs, fs, n = [], [], 0
    for v, f in parts:
        vs.append(v)
        fs.append(f + n)
        n += len(v)
    return np.concatenate(vs), np.concatenate(fs)


def prism_volume(radius, height):
    return SEGMENTS / 2 * radius**2 * np.sin(2 * np.pi / SEGMENTS) * height


def inwards(part):
    v, f = part
    return v, f[:, ::-1]


#: name: (parts, volume, centre of mass) of the solid each mesh bounds.
MESHES = {
    # a can without its lid: 64 open edges; the winding number is 1/2 across the opening
    "open_cylinder.obj": (
        join(cylinder(0.03, 0.1, top=False)),
        prism_volume(0.03, 0.1),
        [0, 0, 0.05],
    ),
    # two boxes overlapping in a 0.03 x 0.04 x 0.04 block: their union
    "overlapping_boxes.obj": (
        join(box([0, 0, 0], [0.06, 0.04, 0.04]), box([0.03, 0, 0], [0.09, 0.04, 0.04])),
        0.09 * 0.04 * 0.04,
        [0.045, 0.02, 0.02],
    ),
    # a convex decomposition's kind: a mug-like shape of a cylinder and three boxes, each overlapping the next
    "pieces.obj": (
        join(
            box([0, 0, 0], [0.04, 0.04, 0.02]),
            box([0, 0, 0.01], [0.04, 0.04, 0.05]),
            box([0.03, 0.01, 0.015], [0.06, 0.03, 0.035]),
        ),
        0.04 * 0.04 * 0.05 + 0.02**3,
        [(0.02 * 0.04 * 0.04 * 0.05 + 0.05 * 0.02**3) / (0.04 * 0.04 * 0.05 + 0.02**3), 0.02, 0.025],
    ),
    # a 60 mm box with a 30 mm cavity at its centre (its shell wound inwards)
    "box_with_cavity.obj": (
        join(box([-0.03] * 3, [0.03] * 3), inwards(box([-0.015] * 3, [0.015] * 3))),
        0.06**3 - 0.03**3,
        [0, 0, 0],
    ),
    # two 40 mm cubes 20 mm apart
    "two_bodies.obj": (
        join(box([0, 0, 0], [0.04, 0.04, 0.04]), box([0.06, 0, 0], [0.1, 0.04, 0.04])),
        2 * 0.04**3,
        [0.05, 0.02, 0.02],
    ),
}


def write_obj(path, v, f):
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in v.tolist()] + [
        f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f.tolist()
    ]
    path.write_text("\n".join(lines) + "\n")


def write_stl(path, v, f):
    lines = ["solid cube_mm"]
    for a, b, c in v[f]:
        n = np.cross(b - a, c - a)
        n = n / np.linalg.norm(n)
        lines += [f"facet normal {n[0]:g} {n[1]:g} {n[2]:g}", "outer loop"]
        lines += [f"vertex {x:g} {y:g} {z:g}" for x, y, z in (a, b, c)]
        lines += ["endloop", "endfacet"]
    path.write_text("\n".join([*lines, "endsolid cube_mm"]) + "\n")


def main():
    for name, ((v, f), _, _) in MESHES.items():
        write_obj(HERE / name, v, f)
    write_stl(HERE / "cube_mm.stl", *box([0, 0, 0], [65, 65, 65]))


if __name__ == "__main__":
    main()
