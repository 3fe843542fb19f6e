"""Random grasp data sets for the benchmarks (built here, so every script is self-contained)."""

import numpy as np


def grasp_arrays(n, seed=0):
    """``n`` random grasps: points, normals, wrist ``(n, 3)``, twist ``(n, 6)``.

    Contacts on a unit sphere around a random centre, normals pointing
    roughly inward, the wrist above the contacts: a few near-degenerate rows
    occur, as in real data.
    """
    rng = np.random.default_rng(seed)
    centre = rng.uniform(-1, 1, (n, 1, 3))
    directions = rng.normal(size=(n, 3, 3))
    directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
    points = centre + directions
    normals = -directions + 0.3 * rng.normal(size=(n, 3, 3))
    wrist = centre[:, 0] + rng.normal(size=(n, 3)) + [0, 0, 2.0]
    twist = rng.normal(size=(n, 6))
    return points, normals, wrist, twist
