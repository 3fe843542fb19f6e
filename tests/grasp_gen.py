"""Random grasps for the tests, built with numpy from a seed (hypothesis draws seeds and scales)."""

import numpy as np


def rotation(rng, n=None):
    """Random proper rotations, ``(n, 3, 3)`` (or ``(3, 3)``), via QR of a Gaussian matrix."""
    shape = (1 if n is None else n, 3, 3)
    q, r = np.linalg.qr(rng.normal(size=shape))
    q = q * np.sign(np.diagonal(r, axis1=-2, axis2=-1))[..., None, :]
    q[np.linalg.det(q) < 0, :, 0] *= -1
    return q[0] if n is None else q


def rigid_pose(rng):
    """A random ``(4, 4)`` rigid pose: a random rotation, a shift in ``[-1, 1)^3``."""
    p = np.eye(4)
    p[:3, :3] = rotation(rng)
    p[:3, 3] = rng.uniform(-1, 1, 3)
    return p


def grasps(rng, n, scale=1.0, offset=0.0):
    """``n`` random grasps well away from every degenerate condition.

    Independent of the engine: contacts are three points of a triangle whose
    every angle exceeds 20 degrees, the wrist sits at least 0.3 x size off its
    plane, and each normal leans at most 60 degrees from the inward direction
    ``centroid - p_i`` tilted toward a random off-plane side.  Returns
    ``points (n,3,3)``, ``normals (n,3,3)`` (random lengths), ``wrist (n,3)``,
    ``twist (n,6)``.
    """
    points = np.empty((0, 3, 3))
    while len(points) < n:
        p = rng.uniform(-1, 1, size=(4 * n, 3, 3))
        a = p[:, 1] - p[:, 0]
        b = p[:, 2] - p[:, 0]
        c = p[:, 2] - p[:, 1]
        cos = [
            np.einsum("ij,ij->i", a, b) / np.linalg.norm(a, axis=1) / np.linalg.norm(b, axis=1),
            -np.einsum("ij,ij->i", a, c) / np.linalg.norm(a, axis=1) / np.linalg.norm(c, axis=1),
            np.einsum("ij,ij->i", b, c) / np.linalg.norm(b, axis=1) / np.linalg.norm(c, axis=1),
        ]
        good = np.all(np.array(cos) < np.cos(np.radians(20)), axis=0)
        points = np.concatenate([points, p[good]])[:n]
    size = np.max(np.linalg.norm(points - points[:, [1, 2, 0]], axis=-1), axis=-1)
    centroid = points.mean(axis=1)
    plane = np.cross(points[:, 1] - points[:, 0], points[:, 2] - points[:, 0])
    plane /= np.linalg.norm(plane, axis=-1, keepdims=True)
    side = np.where(rng.random(n) < 0.5, -1.0, 1.0)[:, None]
    height = rng.uniform(0.3, 2.0, n)[:, None] * size[:, None]
    wrist = centroid + side * height * plane + rng.uniform(-0.5, 0.5, (n, 3)) * size[:, None] * 0.5
    inward = centroid[:, None, :] - points
    inward /= np.linalg.norm(inward, axis=-1, keepdims=True)
    lean = rng.uniform(-1, 1, (n, 3, 1)) * plane[:, None, :]
    normals = inward + lean + 0.3 * rng.normal(size=(n, 3, 3))
    normals *= rng.uniform(0.5, 3.0, (n, 3, 1))
    twist = rng.normal(size=(n, 6))
    twist[:, 3:] *= scale
    return points * scale + offset, normals, wrist * scale + offset, twist


def in_plane(points, normals, which, tilt):
    """``normals`` (``(N, 3, 3)``) with normal ``which[k]`` of grasp ``k`` turned into its contacts' plane,
    plus ``tilt[k]`` (a scalar or ``(N,)``) along that plane's unit normal: a tangent method at or near
    its ``normal-in-contact-plane`` threshold."""
    m = np.cross(points[:, 1] - points[:, 0], points[:, 2] - points[:, 0])
    m /= np.linalg.norm(m, axis=1, keepdims=True)
    rows = np.arange(len(points))
    n = normals[rows, which]
    n = n - np.sum(n * m, axis=1)[:, None] * m
    out = normals.copy()
    out[rows, which] = n / np.linalg.norm(n, axis=1, keepdims=True) + np.reshape(tilt, (-1, 1)) * m
    return out
