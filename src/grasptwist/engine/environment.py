r"""The world around the object: a table under it, boxes beside it, and how far the fingers keep from them.

An :class:`~grasptwist.model.Environment` is a table, the horizontal plane
:math:`z = h` of the grasp frame (gravity along :math:`-z`), and boxes of half sizes
:math:`a` at poses :math:`(R, t)`.  Their signed distances (> 0 outside, < 0 inside) are

.. math::

    \phi_T(x) = x_z - h, \qquad
    \phi_B(x) = \bigl|\max(q, 0)\bigr| + \min\bigl(\max_k q_k, 0\bigr), \quad q = |R^T (x - t)| - a,

both exact, and the environment's is the least of them, :math:`\phi_E = \min(\phi_T, \phi_{B_1}, \ldots)`.
A fingertip sphere of centre :math:`c` and radius :math:`r` is :math:`\phi_E(c) - r` from the
environment (exact); a finger link is as far as its nearest vertex (exact for the table: a linear
function's least over a convex polytope is at a vertex; for a box, exact for the vertices, an upper
bound otherwise, as the links' depths in the object are, :mod:`~grasptwist.engine.collision`).

A finger *keeps its clearance* :math:`c_\min` when every part of it is at least that far:
:math:`\phi_E \ge c_\min` (:data:`CLEARANCE` unless the environment says otherwise).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "CLEARANCE",
    "TABLE",
    "box_distance",
    "clearance_of",
    "environment_distance",
    "has_obstacles",
    "needs_checks",
    "obstacle_name",
    "parts_distance",
    "sphere_distance",
]

#: The least distance a finger keeps from the environment when none is given: 1 mm in a grasp in
#: metres (the bundled grasps' units; it is in the file's units, as every length there).
CLEARANCE = 1e-3

#: The index :func:`environment_distance` gives the table (boxes are 0, 1, ...).
TABLE = -1


def clearance_of(environment) -> float:
    """The clearance an environment asks of the fingers: its own, else :data:`CLEARANCE`.

    >>> from grasptwist.objects import Environment
    >>> clearance_of(Environment(0.0)), clearance_of(Environment(0.0, clearance=0.005))
    (0.001, 0.005)
    """
    return CLEARANCE if environment.clearance is None else float(environment.clearance)


def has_obstacles(environment) -> bool:
    """Whether there is anything to keep clear of (a table or a box).

    >>> from grasptwist.objects import Environment
    >>> has_obstacles(None), has_obstacles(Environment()), has_obstacles(Environment(0.0))
    (False, False, True)
    """
    return environment is not None and (environment.table_height is not None or len(environment.boxes) > 0)


def needs_checks(hand, environment) -> bool:
    """Whether a grasp's fingers have anything to be checked against: an environment with a table or
    a box, or a hand whose links (a URDF's) or fingertip spheres could meet each other.

    >>> from grasptwist.objects import Environment
    >>> needs_checks(None, None), needs_checks(None, Environment(0.0))
    (False, True)
    """
    if has_obstacles(environment):
        return True
    return hand is not None and (hand.source is not None or any(f.tip_radius > 0 for f in hand.fingers))


def box_distance(points, size, pose):
    r"""Signed distance of points from a box: :math:`\phi_B` (module docstring), > 0 outside.

    Parameters
    ----------
    points : (..., 3) array
    size : (3,) array
        Edge lengths along the box's own axes.
    pose : (4, 4) array
        From the box's frame to the points'.

    Returns
    -------
    (...) array

    Examples
    --------
    >>> box_distance([[0, 0, 2.0], [0.5, 0.5, 0.5], [0, 0, 0.75]], [2.0, 2.0, 2.0], np.eye(4)).tolist()
    [1.0, -0.5, -0.25]
    >>> float(box_distance([2.0, 2.0, 1.0], [2.0, 2.0, 2.0], np.eye(4)))  # from the edge: sqrt(2)
    1.4142135623730951
    """
    pose = np.asarray(pose, dtype=float)
    local = (np.asarray(points, dtype=float) - pose[:3, 3]) @ pose[:3, :3]  # R^T (x - t), row by row
    q = np.abs(local) - 0.5 * np.asarray(size, dtype=float)
    return np.linalg.norm(np.maximum(q, 0.0), axis=-1) + np.minimum(q.max(axis=-1), 0.0)


def environment_distance(points, environment):
    r"""Each point's signed distance from the environment, :math:`\phi_E`, and what is nearest.

    Parameters
    ----------
    points : (..., 3) array
        In the grasp frame.
    environment : Environment or None

    Returns
    -------
    distance : (...) array
        ``inf`` with nothing around.
    nearest : (...) int array
        -1 for the table, else the index of the box in ``environment.boxes``.

    Examples
    --------
    >>> from grasptwist.objects import Environment, Obstacle
    >>> env = Environment(0.0, (Obstacle(np.ones(3), np.eye(4)),))
    >>> d, k = environment_distance([[0, 0, 0.6], [3.0, 0, 0.25]], env)
    >>> d.round(12).tolist(), k.tolist()
    ([0.1, 0.25], [0, -1])
    """
    p = np.asarray(points, dtype=float)
    distance = np.full(p.shape[:-1], np.inf)
    nearest = np.full(p.shape[:-1], TABLE)
    if environment is None:
        return distance, nearest
    if environment.table_height is not None:
        distance = p[..., 2] - environment.table_height
    for k, box in enumerate(environment.boxes):
        d = box_distance(p, box.size, box.pose)
        nearest = np.where(d < distance, k, nearest)
        distance = np.minimum(distance, d)
    return distance, nearest


def sphere_distance(centers, radii, environment):
    r"""Fingertip spheres' signed distances from the environment, :math:`\phi_E(c) - r`, and what is nearest.

    ``(..., 3)`` centres and ``(...)`` radii (broadcast) -> ``(...)``, ``(...)`` as :func:`environment_distance`.

    >>> from grasptwist.objects import Environment
    >>> d, _ = sphere_distance([[0, 0, 0.0125]], [0.01], Environment(0.0))
    >>> d.round(12).tolist()
    [0.0025]
    """
    distance, nearest = environment_distance(centers, environment)
    return distance - np.asarray(radii, dtype=float), nearest


def obstacle_name(nearest: int) -> str:
    """How a message names an obstacle: ``the table`` or ``box k`` (1-based, as a file lists them).

    >>> obstacle_name(TABLE), obstacle_name(0)
    ('the table', 'box 1')
    """
    return "the table" if nearest == TABLE else f"box {nearest + 1}"


def parts_distance(parts, links, poses, centers, radii, environment):
    r"""Each part of a hand from the environment: its links (their nearest vertex), then its fingertip spheres.

    A link's vertices come in clusters, each in a ball of centre :math:`c` and radius :math:`\rho`
    (:func:`~grasptwist.engine.collision.clusters`); the signed distance is 1-Lipschitz, so each of a
    cluster's vertices is between :math:`\phi_E(c) - \rho` and :math:`\phi_E(c) + \rho` from the
    environment, and only the clusters that may hold a link's nearest vertex are opened.

    Parameters
    ----------
    parts : LinkClusters
        The links' vertices at home, in clusters (a convex hull's vertices suffice: module docstring).
    links : int
        ``L``.
    poses : (N, L, 4, 4) array
        Each link's pose from home (:func:`~grasptwist.engine.collision.link_poses`).
    centers : (N, F, 3) array
        The fingertip spheres' centres.
    radii : (F,) array

    Returns
    -------
    distance, nearest : (N, L + F) arrays
        As :func:`environment_distance`.

    Examples
    --------
    A link with a vertex 2 mm into the table, a sphere 2.5 mm above it:

    >>> from grasptwist.engine.collision import clusters
    >>> from grasptwist.objects import Environment
    >>> link = clusters([[[0, 0, 0.05], [0, 0, -0.002]]])
    >>> d, k = parts_distance(link, 1, np.eye(4)[None, None], [[[0, 0, 0.0125]]], [0.01], Environment(0.0))
    >>> d.round(12).tolist(), k.tolist()
    ([[-0.002, 0.0025]], [[-1, -1]])
    """
    poses = np.asarray(poses, dtype=float)
    n = len(poses)
    link_d, link_k = np.full((n, links), np.inf), np.full((n, links), TABLE)
    if len(parts.link) and n:
        mine = poses[:, parts.link]  # (N, C, 4, 4): each cluster's link's pose
        rotation, translation = mine[..., :3, :3], mine[..., :3, 3]
        middle = (rotation @ parts.center[:, :, None])[..., 0] + translation
        d = environment_distance(middle, environment)[0]
        bound = np.full((n, links), np.inf)
        rows = np.repeat(np.arange(n), len(parts.link))
        np.minimum.at(bound, (rows, np.tile(parts.link, n)), (d + parts.radius).reshape(-1))
        rows, cols = np.nonzero(d - parts.radius <= bound[:, parts.link])
        v = parts.vertices[cols] @ rotation[rows, cols].swapaxes(-1, -2) + translation[rows, cols, None]
        vd, vk = environment_distance(v, environment)
        low = vd.argmin(axis=1)
        least, which = vd[np.arange(len(low)), low], vk[np.arange(len(low)), low]
        order = np.argsort(-least, kind="stable")  # the nearest written last
        link = parts.link[cols[order]]
        link_d[rows[order], link], link_k[rows[order], link] = least[order], which[order]
    sd, sk = sphere_distance(centers, radii, environment)
    return np.concatenate([link_d, sd], axis=-1), np.concatenate([link_k, sk], axis=-1)
