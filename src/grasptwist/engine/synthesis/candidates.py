r"""Candidate contact triples on a surface: sampled, biased to antipodal pairs, perturbed, told apart.

The surface is given by samples (area-weighted points and unit inward normals), so these
functions work on arrays alone; :mod:`~grasptwist.engine.synthesis.search` draws them
from an object.
"""

from __future__ import annotations

from itertools import permutations

import numpy as np

__all__ = ["ANTIPODAL_SHARE", "PARTNERS", "antipodality", "candidate_triples", "tangent_steps", "triple_distance"]

#: The share of candidates whose first two contacts are an antipodal pair (the rest: uniform).
ANTIPODAL_SHARE = 0.5

#: Partners tried for each first contact of an antipodal pair; the most antipodal is kept.
PARTNERS = 8

_ORDERS = np.array(list(permutations(range(3))))


def antipodality(p1, n1, p2, n2):
    r"""How well two contacts squeeze each other: ``min(n_1 . e, -n_2 . e)``, ``e`` from ``p_1`` to ``p_2``.

    .. math:: a = \min\left(n_1 \cdot e,\; -n_2 \cdot e\right), \qquad e = \frac{p_2 - p_1}{|p_2 - p_1|}

    1 for an antipodal pair (each normal along the line that joins them, inward), at most 0
    when either finger would push away from the other.  ``(..., 3)`` arrays -> ``(...)``.

    >>> float(antipodality(np.array([1.0, 0, 0]), np.array([-1.0, 0, 0]), np.array([-1.0, 0, 0]), np.array([1.0, 0, 0])))
    1.0
    """
    e = p2 - p1
    with np.errstate(invalid="ignore", divide="ignore"):
        e = e / np.linalg.norm(e, axis=-1, keepdims=True)
    return np.nan_to_num(np.minimum(np.sum(n1 * e, axis=-1), -np.sum(n2 * e, axis=-1)), nan=-1.0)


def candidate_triples(points, normals, count, rng, *, antipodal_share=ANTIPODAL_SHARE):
    """``count`` triples of indices into the samples ``points, normals (M, 3)``: ``(count, 3)`` ints.

    A share ``antipodal_share`` of them start with an antipodal pair (for each first
    contact, the most antipodal of :data:`PARTNERS` random partners); every other index
    is uniform over the samples, so that the triples are area-weighted as the samples are.

    >>> rng = np.random.default_rng(0)
    >>> p = rng.normal(size=(50, 3))
    >>> t = candidate_triples(p, -p / np.linalg.norm(p, axis=1, keepdims=True), 10, rng)
    >>> t.shape, bool(((t >= 0) & (t < 50)).all())
    ((10, 3), True)
    """
    m = len(points)
    triples = rng.integers(0, m, size=(count, 3))
    pairs = int(round(count * antipodal_share))
    first = triples[:pairs, 0]
    partners = rng.integers(0, m, size=(pairs, PARTNERS))
    score = antipodality(points[first, None], normals[first, None], points[partners], normals[partners])
    triples[:pairs, 1] = partners[np.arange(pairs), np.argmax(score, axis=1)]
    return triples


def tangent_steps(normals, scale, rng):
    """Random steps of size about ``scale`` in each contact's tangent plane: ``(..., 3)`` unit normals -> ``(..., 3)``.

    >>> n = np.array([[0.0, 0, 1]])
    >>> float(tangent_steps(n, 0.1, np.random.default_rng(1))[0, 2])
    0.0
    """
    step = rng.normal(size=normals.shape) * np.asarray(scale)[..., None]
    return step - np.sum(step * normals, axis=-1, keepdims=True) * normals


def triple_distance(a, b):
    """The distance between grasps: the least over the fingers' orders of the largest contact distance.

    ``a (..., 3, 3)``, ``b (..., 3, 3)`` broadcast -> ``(...)``; it does not depend on the
    order in which either grasp lists its contacts.

    >>> p = np.eye(3)
    >>> float(triple_distance(p, p[::-1])), float(triple_distance(p, p + 0.5))
    (0.0, 0.8660254037844386)
    """
    diff = a[..., None, :, :] - np.asarray(b)[..., _ORDERS, :]  # (..., 6, 3, 3)
    x, y, z = diff[..., 0], diff[..., 1], diff[..., 2]
    square = x * x + y * y + z * z  # (..., 6, 3), summed as numpy.linalg.norm sums it
    # the largest over the fingers, the least over the orders, column by column (numpy's reductions
    # over a short last axis are its slow path), the root last: it keeps the order
    worst = np.maximum(np.maximum(square[..., 0], square[..., 1]), square[..., 2])
    least = worst[..., 0]
    for k in range(1, len(_ORDERS)):
        least = np.minimum(least, worst[..., k])
    return np.sqrt(least)
