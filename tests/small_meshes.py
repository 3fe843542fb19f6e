"""Small meshes made by the tests themselves (issue 35): a cube as an OBJ file in any unit."""

import numpy as np

# A cube's eight corners and twelve triangles, counter-clockwise seen from outside.
CORNERS = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
TRIANGLES = np.array(
    [
        [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
        [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],
    ]
)  # fmt: skip


def cube_obj(path, edge):
    """An OBJ cube of edge ``edge`` centred at its origin."""
    lines = [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in CORNERS * edge / 2]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in TRIANGLES]
    path.write_text("\n".join(lines) + "\n")
    return path
