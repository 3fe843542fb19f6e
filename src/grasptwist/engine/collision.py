r"""Fingers against the object: how deep each finger link's geometry goes into it.

A link's geometry is the vertices of its mesh (a URDF's collision geometry),
held in the hand's root frame at home (every joint at 0).  A link moves with
the first ``j`` joints of its finger, the product of exponentials of
:func:`~grasptwist.engine.kinematics.forward_kinematics`:

.. math::

    v(q) = g_j(q)\, v_0, \qquad g_j(q) = e^{[S_1] q_1} \cdots e^{[S_j] q_j} .

Its penetration depth is the deepest of its vertices inside the object,

.. math::

    d = \max\Bigl(0,\ \max_{v} -\phi\bigl(v(q)\bigr)\Bigr),

with :math:`\phi` the object's signed distance (> 0 outside,
:func:`~grasptwist.engine.objects.geometry.signed_distance`): exact for the
vertices, so exact for a link whose deepest point is a vertex (a flat face
or a corner pushed into the object).  An object's edge or corner poking into
a face of a link between its vertices is seen only as deep as the nearest
vertices go: the depth is a lower bound, as close as the link's mesh is fine
(the TriFinger's collision meshes have vertices every few millimetres).

Speed comes from never asking the object about far vertices (the checks are
conservative, so nothing is missed): each link's vertices are cut into
compact *clusters* of at most :data:`CLUSTER` vertices, each in a ball of
centre :math:`c` and radius :math:`\rho`; a cluster whose ball misses the
object's bounding box (axis-aligned in the object's own frame), or whose
centre is farther than :math:`\rho` from the object (:math:`\phi(c) > \rho`:
the signed distance is 1-Lipschitz), has no vertex inside it.

The fingertip's own contact is no collision: :func:`tip_sphere` says which
vertices of a finger's tip link lie on its fingertip sphere (within
``tip_radius`` plus :data:`COLLISION_TOL` times the object's size of the tip
link's origin, the sphere's centre); they are left out.  The rest of the tip
link (a stem holding the sphere) still counts.
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np

from . import se3
from .kinematics import forward_kinematics, joint_motion
from .objects import primitives
from .objects.geometry import object_size, signed_distance

__all__ = [
    "CLUSTER",
    "COLLISION_TOL",
    "LinkGeometry",
    "LinkClusters",
    "clusters",
    "collision_tolerance",
    "link_poses",
    "penetration_depths",
    "tip_sphere",
    "HULL_MERGE",
    "LinkHulls",
    "convex_planes",
    "convex_edges",
    "hull_depth",
    "hull_penetration",
    "link_hulls",
    "tip_centers_at",
    "finger_overlaps",
]

#: Depths at most this, times the object's size (its bounding box's diagonal), are no collision:
#: round-off and tessellation (a 65 mm cube: 0.11 mm).  It also pads the fingertip's sphere.
COLLISION_TOL = 1e-3

#: How much of a link's extent Qhull may merge its hull's facets by (:func:`convex_planes`): the
#: TriFinger's hulls keep 80-230 of 200-580 vertices, each plane moved out to the farthest vertex.
HULL_MERGE = 2e-3

#: Most vertices of a hull's cluster (:class:`LinkHulls`): a TriFinger link's 80-230 hull
#: vertices in 8-16 clusters, of which a link near another opens a few.
HULL_CLUSTER = 16

#: How many of the least edge axes of a pair of hulls :func:`hull_penetration` measures by every vertex.
_EDGE_AXES = 4

#: Most vertices of one cluster (:func:`clusters`): small enough that a cluster near the
#: object asks about few far vertices, large enough that far clusters are few (measured with
#: ``bench/collisions.py``: 32 beats 16 and 64 by 1.5 to 2.5 times).
CLUSTER = 32


class LinkGeometry(NamedTuple):
    """One finger link's collision geometry.

    Attributes
    ----------
    finger : int
        The finger's index in ``hand.fingers``.
    link : str
        The link's name in its URDF.
    joints : int
        How many of the finger's movable joints (base first) move it.
    vertices : numpy.ndarray
        ``(V, 3)`` in the hand's root frame at home (every joint at 0).
    faces : numpy.ndarray
        ``(F, 3)`` int, triangles of ``vertices`` (pictures, the library baseline of ``bench/``).
    """

    finger: int
    link: str
    joints: int
    vertices: np.ndarray
    faces: np.ndarray


class LinkClusters(NamedTuple):
    """Links' vertices cut into compact clusters (:func:`clusters`), padded to one width.

    Attributes
    ----------
    link : numpy.ndarray
        ``(C,)`` int, the link each cluster belongs to.
    center, radius : numpy.ndarray
        ``(C, 3)``, ``(C,)``: each cluster's ball at home.
    vertices : numpy.ndarray
        ``(C, CLUSTER, 3)``: a cluster's vertices, padded by repeating its first.
    """

    link: np.ndarray
    center: np.ndarray
    radius: np.ndarray
    vertices: np.ndarray


def tip_sphere(vertices, center, radius, tol):
    r"""Which vertices lie on a fingertip sphere: within ``radius + tol`` of its centre.

    .. math::

        |v - c| \le r + \varepsilon

    Parameters
    ----------
    vertices : (..., 3) array
    center : (..., 3) array
        The tip link's origin (the sphere's centre).
    radius : float or (...) array
        ``Finger.tip_radius`` (0: a point tip, only the centre is on it).
    tol : float

    Returns
    -------
    (...) bool array

    >>> tip_sphere([[0, 0, 0.01], [0, 0, 0.02]], [0, 0, 0], 0.01, 1e-4).tolist()
    [True, False]
    """
    v = np.asarray(vertices, dtype=float)
    return np.linalg.norm(v - np.asarray(center, dtype=float), axis=-1) <= np.asarray(radius) + tol


def clusters(vertices, size: int = CLUSTER) -> LinkClusters:
    """Each link's vertices cut into clusters of at most ``size``, halving along the longest side.

    Parameters
    ----------
    vertices : sequence of (V_l, 3) arrays
        One per link (a link without vertices gets no cluster).
    size : int

    Returns
    -------
    LinkClusters

    >>> c = clusters([np.arange(30.0).reshape(10, 3)], size=4)
    >>> c.link.tolist(), c.vertices.shape, bool((c.radius > 0).all())
    ([0, 0, 0, 0], (4, 4, 3), True)
    """
    links, groups = [], []
    for index, v in enumerate(vertices):
        stack = [np.asarray(v, dtype=float).reshape(-1, 3)]
        while stack:
            part = stack.pop()
            if len(part) == 0:
                continue
            if len(part) <= size:
                links.append(index)
                groups.append(part)
                continue
            axis = np.argmax(np.ptp(part, axis=0))
            order = np.argsort(part[:, axis], kind="stable")
            half = len(part) // 2
            stack += [part[order[:half]], part[order[half:]]]
    padded = np.array([np.concatenate([g, np.repeat(g[:1], size - len(g), axis=0)]) for g in groups]).reshape(
        -1, size, 3
    )
    center = 0.5 * (padded.min(axis=1) + padded.max(axis=1))
    radius = np.linalg.norm(padded - center[:, None], axis=-1).max(axis=1) if len(groups) else np.zeros(0)
    return LinkClusters(np.array(links, dtype=int), center, radius, padded)


def link_poses(hand, geometry, positions, frames=None):
    r"""Each link's motion from home, :math:`g_j(q)`, at joint ``positions``, seen from a moving object.

    With the object moved by :math:`P` (a path's pose), the link is where
    :math:`P^{-1} g_j(q)` puts it against the object where the grasp has it.

    Parameters
    ----------
    hand : Hand
    geometry : sequence of LinkGeometry
    positions : (N, n_joints) array
        In ``hand.joint_names`` order.
    frames : (N, 4, 4) array, optional
        The object's motion :math:`P` at each configuration; None: the identity.

    Returns
    -------
    (N, L, 4, 4) array
        Link ``l``'s vertices are ``R v + t`` of its pose.

    Examples
    --------
    >>> from grasptwist.model import Finger
    >>> hand = type("H", (), {"fingers": [Finger("1", None, (), np.array([[0, 0, 1.0, 0, 0, 0]]),
    ...     np.zeros((1, 3)), None, 1.0, (0,))]})
    >>> link = LinkGeometry(0, "a", 1, np.zeros((1, 3)), np.zeros((0, 3), int))
    >>> link_poses(hand, [link], [[np.pi / 2]])[0, 0, :2, :2].round(12).tolist()
    [[0.0, -1.0], [1.0, 0.0]]
    """
    q = np.asarray(positions, dtype=float)
    out = np.empty(q.shape[:-1] + (len(geometry), 4, 4))
    out[...] = np.eye(4)
    for f, finger in enumerate(hand.fingers):
        mine = [(i, g.joints) for i, g in enumerate(geometry) if g.finger == f and g.joints]
        # g_j = g_(j-1) e^([S_j] q_j), one exponential per joint shared by the finger's links
        rotation, translation = np.eye(3), np.zeros(3)
        for j in range(max((joints for _, joints in mine), default=0)):
            r, t = joint_motion(finger.screws[j], q[..., finger.joint_index[j]])
            rotation, translation = rotation @ r, (rotation @ t[..., None])[..., 0] + translation
            for i in (i for i, joints in mine if joints == j + 1):
                out[..., i, :3, :3], out[..., i, :3, 3] = rotation, translation
    if frames is not None:
        frames = np.asarray(frames, dtype=float)
        rotation, translation = se3.inverse(frames[..., :3, :3], frames[..., :3, 3])
        back = np.zeros(frames.shape)
        back[..., :3, :3], back[..., :3, 3], back[..., 3, 3] = rotation, translation, 1.0
        out = back[..., None, :, :] @ out
    return out


def collision_tolerance(obj) -> float:
    """The depth below which a link touching ``obj`` is no collision: :data:`COLLISION_TOL` times its size."""
    return COLLISION_TOL * object_size(obj)


def penetration_depths(obj, parts: LinkClusters, poses, n_links: int | None = None):
    r"""Per link, how deep its vertices go into the object (0 when apart).

    Parameters
    ----------
    obj : GraspObject
        In the grasp frame (the hand's root frame).
    parts : LinkClusters
        The links' vertices at home (:func:`clusters`).
    poses : (N, L, 4, 4) array
        Each link's pose from home (:func:`link_poses`).
    n_links : int, optional
        ``L`` (default: from ``poses``).

    Returns
    -------
    (N, L) array
        :math:`\max(0, \max_v -\phi(v))` over each link's vertices.

    Examples
    --------
    >>> from grasptwist.model import GraspObject, Shape
    >>> box = GraspObject(Shape("box", np.array([2.0, 2.0, 2.0])), np.eye(4))
    >>> parts = clusters([[[0.0, 0.0, 0.75], [0.0, 0.0, 3.0]], [[5.0, 0.0, 0.0]]])
    >>> penetration_depths(box, parts, np.broadcast_to(np.eye(4), (1, 2, 4, 4))).tolist()
    [[0.25, 0.0]]
    """
    poses = np.asarray(poses, dtype=float)
    n, links = poses.shape[0], poses.shape[1] if n_links is None else n_links
    depth = np.zeros((n, links))
    if len(parts.link) == 0 or n == 0:
        return depth
    # in the object's own frame, where its bounding box is axis-aligned
    back, shift = se3.inverse(obj.pose[:3, :3], obj.pose[:3, 3])
    rotation = back @ poses[..., :3, :3]  # (N, L, 3, 3)
    translation = _apply(back, poses[..., :3, 3]) + shift
    box = _box(obj.shape)
    rows, cols, center = _near(parts, rotation, translation, box)
    if len(rows) == 0:
        return depth
    distance = _own_distance(obj)
    phi = distance(center)
    radius, link = parts.radius[cols], parts.link[cols]
    # branch and bound: every vertex of a cluster is at least -phi - r deep and at most -phi + r
    # (the signed distance is 1-Lipschitz), so only a cluster that may hold the deepest vertex is opened
    bound = np.zeros((n, links))
    np.maximum.at(bound, (rows, link), -phi - radius)
    open_ = -phi + radius >= bound[rows, link]
    rows, cols, link = rows[open_], cols[open_], link[open_]
    r, t = rotation[rows, link], translation[rows, link]
    v = parts.vertices[cols] @ r.swapaxes(-1, -2) + t[:, None]
    deepest = -distance(v).min(axis=1)
    np.maximum.at(depth, (rows, link), deepest)
    return depth


def _own_distance(obj):
    """The object's signed distance of points in its own frame, ``(..., 3) -> (...)``: a primitive's
    closed form straight (the points are finite: a link's vertices moved by finite poses)."""
    if obj.shape.kind == "mesh":
        here = replace(obj, pose=np.eye(4))
        return lambda x: signed_distance(here, x)
    kind, size = obj.shape.kind, np.asarray(obj.shape.size, dtype=float)
    return lambda x: primitives.signed_distance(kind, size, x.reshape(-1, 3)).reshape(x.shape[:-1])


def _near(parts, rotation, translation, box):
    """The (configuration, cluster) pairs whose balls reach the object's bounding box, and the clusters'
    centres there: first each link's ball (holding its clusters'), then theirs, every link at once
    (``rotation (N, L, 3, 3)``, ``translation (N, L, 3)``; a link's clusters are consecutive)."""
    links, first, count = np.unique(parts.link, return_index=True, return_counts=True)
    middle = 0.5 * (np.minimum.reduceat(parts.center, first) + np.maximum.reduceat(parts.center, first))
    reach = np.maximum.reduceat(_length(parts.center - np.repeat(middle, count, axis=0)) + parts.radius, first)
    ball = (rotation[:, links] @ middle[:, :, None])[..., 0] + translation[:, links]
    rows, which = np.nonzero(_outside(ball, box) <= reach)
    # every cluster of each such (configuration, link)
    k = count[which]
    pair = np.repeat(np.arange(len(rows)), k)
    cols = first[which][pair] + np.arange(k.sum()) - np.repeat(np.cumsum(k) - k, k)
    rows, link = rows[pair], parts.link[cols]
    moved = (rotation[rows, link] @ parts.center[cols, :, None])[..., 0] + translation[rows, link]
    hit = _outside(moved, box) <= parts.radius[cols]
    return rows[hit], cols[hit], moved[hit]


def _outside(points, box):
    """How far points are outside an axis-aligned box ``(low, high)`` (0 inside)."""
    low, high = box
    return _length(np.maximum(np.maximum(low - points, points - high), 0.0))


def _length(v):
    """``|v|`` over the last axis of 3, summed in ``numpy.linalg.norm``'s order (the same numbers),
    without its reduction over a short last axis (three times slower: the collision tests' inner loop)."""
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    return np.sqrt(x * x + y * y + z * z)


def _apply(r, x):
    """``R x`` over batches."""
    return (r @ x[..., None])[..., 0]


def _box(shape):
    """The corners ``(3,), (3,)`` of the shape's bounding box in its own frame."""
    if shape.kind == "mesh":
        return shape.vertices.min(axis=0), shape.vertices.max(axis=0)
    s = np.asarray(shape.size, dtype=float)
    half = {
        "box": lambda: s / 2,
        "sphere": lambda: np.full(3, s[0]),
        "cylinder": lambda: np.array([s[0], s[0], s[1] / 2]),
        "capsule": lambda: np.array([s[0], s[0], s[1] / 2 + s[0]]),
    }[shape.kind]()
    return -half, half


class LinkHulls(NamedTuple):
    """Finger links as convex hulls (:func:`link_hulls`), padded to one width.

    Attributes
    ----------
    links : tuple of LinkGeometry
        The links (their fingers, joints and names).
    vertices : numpy.ndarray
        ``(L, H, 3)`` each hull's vertices at home, padded by repeating its first.
    planes : numpy.ndarray
        ``(L, K, 4)`` each hull's faces ``(n, d)``, ``n . x + d <= 0`` inside, ``|n| = 1``, padded
        by repeating its first.
    center, radius : numpy.ndarray
        ``(L, 3)``, ``(L,)``: a ball holding each hull at home.
    parts : LinkClusters
        The hulls' vertices in clusters of :data:`HULL_CLUSTER` (:func:`clusters`): a cluster whose
        ball lies beyond a face plane of another link has no vertex inside it.
    edges : numpy.ndarray
        ``(L, E, 4, 3)`` each hull's edges between faces of different planes at home: its direction,
        its two faces' normals and its first end (:func:`convex_edges`), padded by repeating its first.
    """

    links: tuple
    vertices: np.ndarray
    planes: np.ndarray
    center: np.ndarray
    radius: np.ndarray
    parts: LinkClusters
    edges: np.ndarray


def convex_planes(vertices, merge=HULL_MERGE):
    r"""The convex hull of points, its facets merged: its vertices ``(H, 3)`` and face planes ``(K, 4)`` (:class:`LinkHulls`).

    Qhull (scipy) merges facets whose centrums are within ``merge`` times the points' extent of
    their neighbours' planes (``C-``): the hull it gives is the exact one to about that much
    (a point's depth within 2.5 times it, tests/engine/test_environment.py).  Each merged plane is
    moved out to the farthest vertex, so that the planes hold the exact hull.  Geometry that
    bounds no solid (a point, a segment, a flat piece: Qhull refuses it) is thickened into one,
    the points' hull grown by a cube of half-width ``merge`` times their extent (``1e-9`` times
    their distance from the origin, at least ``1e-9``, for a single point), :math:`H \oplus
    [-\epsilon, \epsilon]^3`: a thin solid about it.

    >>> v, planes = convex_planes(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [0.1, 0.1, 0.1]]))
    >>> len(v), len(planes), float(hull_depth([0.1, 0.1, 0.1], planes).round(12))
    (4, 4, 0.1)
    >>> v, planes = convex_planes([[0, 0, 0], [1, 0, 0]])  # a segment: a slab 2e-3 wide about it
    >>> len(v), len(planes), float(hull_depth([0.5, 0, 0], planes).round(12))
    (8, 6, 0.002)
    """
    return _merged_hull(vertices, merge)[:2]


def _merged_hull(vertices, merge):
    """:func:`convex_planes`' vertices and planes, and the hull's edges (:func:`convex_edges`)."""
    from scipy.spatial import ConvexHull, QhullError  # as the closure's epsilon: with the first hull

    v = np.asarray(vertices, dtype=float).reshape(-1, 3)
    extent = float(np.ptp(v, axis=0).max())
    try:
        hull = ConvexHull(v, qhull_options=f"C-{merge * extent:.6g}")
    except QhullError:
        half = merge * extent or 1e-9 * max(1.0, float(np.abs(v).max()))
        cube = half * np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).reshape(3, -1).T
        v = (v[:, None] + cube).reshape(-1, 3)
        hull = ConvexHull(v)
    planes = np.unique(hull.equations, axis=0)
    kept = v[hull.vertices]
    planes[:, 3] -= (kept @ planes[:, :3].T + planes[:, 3]).max(axis=0)
    return kept, planes, convex_edges(v, hull.simplices, hull.neighbors, hull.equations[:, :3])


def convex_edges(points, simplices, neighbors, normals):
    """A triangulated convex hull's edges between faces of different normals: ``(E, 4, 3)``, each its
    unit direction, its two faces' normals (the arc of the hull's Gauss map the edge is) and its first end.

    ``simplices``, ``neighbors`` ``(T, 3)`` int (Qhull's: neighbour ``j`` is opposite vertex ``j``),
    ``normals`` ``(T, 3)``; an edge inside a merged facet (one normal on both sides) is none.

    >>> from scipy.spatial import ConvexHull
    >>> h = ConvexHull(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]))
    >>> convex_edges(h.points, h.simplices, h.neighbors, h.equations[:, :3]).shape
    (6, 4, 3)
    """
    t, j = np.nonzero(np.arange(len(simplices))[:, None] < neighbors)
    start = simplices[t, (j + 1) % 3]
    end = simplices[t, (j + 2) % 3]
    one, two = normals[t], normals[neighbors[t, j]]
    bent = (one * two).sum(axis=1) < 1 - 1e-12
    d = points[end[bent]] - points[start[bent]]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return np.stack([d, one[bent], two[bent], points[start[bent]]], axis=1).reshape(-1, 4, 3)


def hull_depth(points, planes):
    r"""How deep points are inside a convex hull, :math:`\delta(x) = -\max_k (n_k \cdot x + d_k)` (< 0 outside).

    ``(..., 3)`` points, ``(..., K, 4)`` planes (their leading axes broadcast) -> ``(...)``; exact
    inside, outside a lower bound of the distance.

    >>> cube = np.array([[1, 0, 0, -1], [-1, 0, 0, -1], [0, 1, 0, -1], [0, -1, 0, -1], [0, 0, 1, -1], [0, 0, -1, -1.0]])
    >>> hull_depth([[0, 0, 0.5], [0, 0, 3.0]], cube).tolist()
    [0.5, -2.0]
    """
    planes = np.asarray(planes, dtype=float)
    x = np.asarray(points, dtype=float)[..., None, :]
    return -((x @ planes[..., :3].swapaxes(-1, -2))[..., 0, :] + planes[..., 3]).max(axis=-1)


def link_hulls(geometry) -> LinkHulls:
    """Each finger link's convex hull (:class:`LinkHulls`) from its geometry at home; links without vertices are left out.

    >>> link = LinkGeometry(0, "a", 1, np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]), np.zeros((0, 3), int))
    >>> h = link_hulls([link])
    >>> h.vertices.shape, h.planes.shape, h.center.tolist()
    ((1, 4, 3), (1, 4, 4), [[0.5, 0.5, 0.5]])
    """
    links = tuple(g for g in geometry if len(g.vertices))
    hulls = [_merged_hull(g.vertices, HULL_MERGE) for g in links]
    vertices, planes, edges = (_padded([h[i] for h in hulls], shape) for i, shape in enumerate([(3,), (4,), (4, 3)]))
    center = 0.5 * (vertices.min(axis=1) + vertices.max(axis=1)) if len(links) else np.zeros((0, 3))
    radius = np.linalg.norm(vertices - center[:, None], axis=-1).max(axis=1) if len(links) else np.zeros(0)
    parts = clusters([h[0] for h in hulls], HULL_CLUSTER)
    return LinkHulls(links, vertices, planes, center, radius, parts, edges)


def _padded(arrays, shape):
    """Arrays of rows stacked ``(L, W, *shape)``, each padded to the widest by repeating its first row."""
    width = max((len(a) for a in arrays), default=1)
    return np.array([np.concatenate([a, np.repeat(a[:1], width - len(a), axis=0)]) for a in arrays]).reshape(
        (-1, width) + shape
    )


def tip_centers_at(hand, tips, positions):
    """Each finger's tip point (its tip link's origin, its fingertip sphere's centre) at joint positions.

    ``hand`` (``F`` fingers), ``tips (F, 4, 4)`` their tip poses at home, ``positions (N, n_joints)`` ->
    ``(N, F, 3)``, by :func:`~grasptwist.engine.kinematics.forward_kinematics`.
    """
    q = np.asarray(positions, dtype=float)
    out = np.empty(q.shape[:-1] + (len(hand.fingers), 3))
    for f, finger in enumerate(hand.fingers):
        state = forward_kinematics(finger.screws, finger.points, tips[f], q[..., list(finger.joint_index)])
        out[..., f, :] = state.tip[..., :3, 3]
    return out


def finger_overlaps(hulls: LinkHulls, poses, centers, radii):
    r"""How deep the parts of different fingers go into each other (module docstring).

    Two links: the deepest vertex of either inside the other; with none inside, the least
    translation that parts them, :func:`hull_penetration` (hulls crossing edge through edge).

    The parts are the links (``L``, :class:`LinkHulls`), then the fingertip spheres (``F``).

    Parameters
    ----------
    hulls : LinkHulls
    poses : (N, L, 4, 4) array
        Each link's pose from home (:func:`link_poses` of ``hulls.links``).
    centers : (N, F, 3) array
        The fingertip spheres' centres (:func:`tip_centers_at`); sphere ``f`` is finger ``f``'s.
    radii : (F,) array
        Their radii (0: a point, never in a collision of its own).

    Returns
    -------
    (N, L + F, L + F) array
        Symmetric; 0 for parts of one finger and parts apart.

    Examples
    --------
    Two tip spheres of 10 mm whose centres are 15 mm apart overlap by 5 mm:

    >>> d = finger_overlaps(link_hulls([]), np.zeros((1, 0, 4, 4)), [[[0, 0, 0], [0.015, 0, 0]]], [0.01, 0.01])
    >>> d.round(12).tolist()
    [[[0.0, 0.005], [0.005, 0.0]]]
    """
    poses = np.asarray(poses, dtype=float)
    c = np.asarray(centers, dtype=float)
    r = np.asarray(radii, dtype=float)
    n, links, tips = len(c), len(hulls.links), c.shape[1]
    parts = links + tips
    depth = np.zeros((n, parts, parts))
    finger = np.array([g.finger for g in hulls.links] + list(range(tips)), dtype=int)
    ball = np.concatenate([_apply(poses[..., :3, :3], hulls.center) + poses[..., :3, 3], c], axis=1)
    reach = np.concatenate([hulls.radius, r])
    a, b = np.triu_indices(parts, 1)
    keep = (finger[a] != finger[b]) & (reach[a] + reach[b] > 0)
    a, b = a[keep], b[keep]
    rows, pair = np.nonzero(_length(ball[:, a] - ball[:, b]) < (reach[a] + reach[b])[None])
    a, b = a[pair], b[pair]  # a < b: a link before a sphere
    found = np.zeros(len(rows))
    both = b < links
    found[both] = _hull_overlaps(hulls, poses, rows[both], a[both], b[both])
    mixed = (a < links) & (b >= links)
    found[mixed] = _sphere_in_hull(
        hulls, poses, rows[mixed], a[mixed], c[rows[mixed], b[mixed] - links], r[b[mixed] - links]
    )
    two = a >= links
    gap = np.linalg.norm(c[rows[two], a[two] - links] - c[rows[two], b[two] - links], axis=-1)
    found[two] = r[a[two] - links] + r[b[two] - links] - gap
    found = np.maximum(found, 0.0)
    depth[rows, a, b] = found
    depth[rows, b, a] = found
    return depth


def _into(poses, rows, a, b):
    """The rigid motion that takes link ``a``'s home geometry to where link ``b``'s home frame sees it
    at configuration ``rows``: ``g_b^{-1} g_a``, as ``(R, t)``."""
    back, shift = se3.inverse(poses[rows, b, :3, :3], poses[rows, b, :3, 3])
    return back @ poses[rows, a, :3, :3], _apply(back, poses[rows, a, :3, 3]) + shift


def _vertex_overlaps(hulls, poses, rows, a, b):
    """The deepest vertex of either of two links inside the other (exact for the vertices; a lower bound
    of :func:`hull_penetration`), and which pairs are apart by a face plane of one: the other's ball, or
    each ball of its vertices' clusters, beyond it (pairs not found apart may be apart all the same).
    A cluster whose ball lies beyond a face plane of the other is not opened."""
    out, apart = np.zeros(len(rows)), np.zeros(len(rows), dtype=bool)
    parts = hulls.parts
    for one, other in ((a, b), (b, a)):
        rotation, translation = _into(poses, rows, one, other)
        centre = _apply(rotation, hulls.center[one]) + translation
        near = hull_depth(centre, hulls.planes[other]) >= -hulls.radius[one]
        apart |= ~near
        near = np.flatnonzero(near)
        for start in range(0, len(near), 256):
            k = near[start : start + 256]
            # the planes carried to link ``one``'s home frame: n' = R^T n, d' = d + n . t
            planes = hulls.planes[other[k]]
            normal = planes[..., :3] @ rotation[k]  # (k, K, 3)
            offset = planes[..., 3] + (planes[..., :3] @ translation[k, :, None])[..., 0]
            # every cluster of link ``one`` (consecutive, so a pair's rows are consecutive): (pair, cluster)
            pair, cluster = np.nonzero(parts.link[None, :] == one[k, None])
            s = (normal[pair] @ parts.center[cluster, :, None])[..., 0] + offset[pair] - parts.radius[cluster, None]
            first = np.flatnonzero(np.r_[True, pair[1:] != pair[:-1]])
            apart[k[pair[first]]] |= (np.minimum.reduceat(s, first, axis=0) > 0).any(axis=1)
            opened = s.max(axis=1) <= 0
            pair, cluster = pair[opened], cluster[opened]
            depth = parts.vertices[cluster] @ normal[pair].swapaxes(1, 2) + offset[pair, None]  # (m, 16, K)
            np.maximum.at(out, k[pair], -depth.max(axis=2).min(axis=1))
    return out, apart


def _hull_overlaps(hulls, poses, rows, a, b):
    """How deep pairs of links go into each other: their deepest vertex inside the other
    (:func:`_vertex_overlaps`), or with none inside and not apart, :func:`hull_penetration` (in
    link ``a``'s home frame)."""
    out, apart = _vertex_overlaps(hulls, poses, rows, a, b)
    todo = np.flatnonzero(~apart & (out <= 0))
    if not todo.size:
        return out
    # each pair of links with its own vertices, faces and edges (not padded to the most of any link)
    nv, nk, ne = (
        1 + (x != x[:, :1]).reshape(len(x), x.shape[1], -1).any(axis=2).sum(axis=1) for x in hulls[1:3] + (hulls.edges,)
    )
    links, group = np.unique(np.stack([a[todo], b[todo]], axis=1), axis=0, return_inverse=True)
    for (one, other), same in zip(links, np.arange(len(links))[:, None] == group.ravel()[None]):
        k = todo[same]
        rotation, translation = _into(poses, rows[k], b[k], a[k])
        edges = hulls.edges[other, : ne[other]] @ rotation[:, None].swapaxes(-1, -2)
        edges[..., 3, :] += translation[:, None]
        out[k] = hull_penetration(
            *(np.broadcast_to(x, (len(k),) + x.shape) for x in _trimmed(hulls, one, nv, nk, ne)),
            hulls.vertices[other, : nv[other]] @ rotation.swapaxes(-1, -2) + translation[:, None],
            hulls.planes[other, : nk[other], :3] @ rotation.swapaxes(-1, -2),
            edges,
        )
    return out


def _trimmed(hulls, link, nv, nk, ne):
    """A link's hull vertices, face normals and edges at home, without padding."""
    return hulls.vertices[link, : nv[link]], hulls.planes[link, : nk[link], :3], hulls.edges[link, : ne[link]]


def hull_penetration(va, na, ea, vb, nb, eb):
    r"""How far two convex hulls go into each other: the least translation that parts them (0 when apart).

    By the separating axis theorem, with :math:`h_X(u) = \max_{v \in X} u \cdot v` a hull's support,

    .. math::

        D = \max\Bigl(0,\ \min_u \bigl(h_A(u) + h_B(-u)\bigr)\Bigr)

    over the axes :math:`u` of the faces of :math:`A - B` (its distance from the origin along them):
    A's face normals, B's reversed, and the cross products :math:`e_a \times e_b` of edges whose arcs on
    the Gauss map cross (:func:`convex_edges`; every other axis gives more, so any axis bounds it).  A face normal with
    :math:`h_A(u) + h_B(-u) \le 0` separates them, and then no edge is tried.

    Parameters
    ----------
    va, vb : (P, H, 3) arrays
        The hulls' vertices, both in one frame.
    na, nb : (P, K, 3) arrays
        Their faces' unit outward normals.
    ea, eb : (P, E, 4, 3) arrays
        Their edges: direction, its two faces' normals and a point of it (:func:`convex_edges`).

    Returns
    -------
    (P,) array

    Examples
    --------
    Two unit cubes, the second turned 45 degrees about x and about y and 1.2 above the first: no
    corner of either is inside the other, its lowest edge crosses the first's top face, 0.154 deep
    (the edges' axis):

    >>> from scipy.spatial import ConvexHull
    >>> from grasptwist.engine.se3 import rotvec_to_matrix
    >>> def hull(points):
    ...     h = ConvexHull(points)
    ...     e = convex_edges(h.points, h.simplices, h.neighbors, h.equations[:, :3])
    ...     return points[None], h.equations[None, :, :3], e[None]
    >>> cube = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)])
    >>> turn = rotvec_to_matrix([0, np.pi / 4, 0]) @ rotvec_to_matrix([np.pi / 4, 0, 0])
    >>> hull_penetration(*hull(cube), *hull(cube @ turn.T + [0, 0, 1.2])).round(4).tolist()
    [0.1536]
    """
    va, vb = np.asarray(va, float), np.asarray(vb, float)
    normals = np.concatenate([na, -np.asarray(nb, float)], axis=1)  # the faces of A - B: A's normals, -B's
    face = (va @ normals.swapaxes(1, 2)).max(axis=1) - (vb @ normals.swapaxes(1, 2)).min(axis=1)
    out = face.min(axis=1)
    todo = np.flatnonzero(out > 0)
    if todo.size:
        out[todo] = np.minimum(out[todo], _edge_depth(va[todo], ea[todo], vb[todo], eb[todo]))
    return np.maximum(out, 0.0)


def _edge_depth(va, ea, vb, eb):
    """The least :math:`h_A(u) + h_B(-u)` over the cross products of edges whose Gauss arcs cross,
    the arc of ``A``'s edge (normals ``p1``, ``p2``) and of ``-B``'s (``q1``, ``q2``): each straddles
    the other's great circle, on the same side (``inf``: none).  Arcs whose caps (about their
    middles, as wide as half the arc) are apart are not tried."""
    # caps apart: m_a . m_b < cos(r_a + r_b) = cos r_a cos r_b - sin r_a sin r_b, one product in 5-d
    pair, i, j = np.nonzero(_cap(ea[..., 1:, :], -1) @ _cap(-eb[..., 1:, :], 1).swapaxes(1, 2) >= 0)
    p1, p2, q1, q2 = ea[pair, i, 1], ea[pair, i, 2], -eb[pair, j, 1], -eb[pair, j, 2]
    n1, n2 = np.cross(p1, p2), np.cross(q1, q2)
    s1, s2 = _dot(q1, n1), _dot(p2, n2)
    cross = (s1 * _dot(q2, n1) < 0) & (_dot(p1, n2) * s2 < 0) & (s1 * s2 > 0)
    pair, i, j = pair[cross], i[cross], j[cross]
    u = np.cross(ea[pair, i, 0], eb[pair, j, 0])
    size = _length(u)
    ok = size > 1e-9
    pair, u = pair[ok], u[ok] / size[ok, None]
    i, j = i[ok], j[ok]
    u *= np.sign(_dot(u, ea[pair, i, 1] + ea[pair, i, 2]))[:, None]
    # along a face of A - B the edges are the supports: h_A(u) + h_B(-u) = u . (a - b); the least
    # few of each pair measured by every vertex (faces merged within HULL_MERGE bend the arcs a little)
    guess = _dot(u, ea[pair, i, 3] - eb[pair, j, 3])
    order = np.lexsort((guess, pair))
    pair, u = pair[order], u[order]
    first = np.flatnonzero(np.r_[True, pair[1:] != pair[:-1]])
    keep = np.arange(len(pair)) - np.repeat(first, np.diff(np.r_[first, len(pair)])) < _EDGE_AXES
    pair, u = pair[keep], u[keep]
    depth = (va[pair] @ u[..., None]).max(axis=(1, 2)) - (vb[pair] @ u[..., None]).min(axis=(1, 2))
    out = np.full(len(va), np.inf)
    np.minimum.at(out, pair, depth)
    return out


def _cap(ends, sign):
    """The cap holding arcs of a sphere ``(..., 2, 3)``: its centre, and the cosine and sine of its
    radius, the first times ``sign``, ``(..., 5)``."""
    m = ends[..., 0, :] + ends[..., 1, :]
    size = _length(m)
    c = np.minimum(0.5 * size, 1.0)
    return np.concatenate([m / size[..., None], sign * c[..., None], np.sqrt(1 - c * c)[..., None]], axis=-1)


def _dot(x, y):
    """``x . y`` over the last axis of 3."""
    return x[..., 0] * y[..., 0] + x[..., 1] * y[..., 1] + x[..., 2] * y[..., 2]


def _sphere_in_hull(hulls, poses, rows, link, centers, radii):
    """How deep fingertip spheres go into links: ``r`` less the centre's distance from the hull,
    exact inside and over a face, else the nearest vertex's."""
    back, shift = se3.inverse(poses[rows, link, :3, :3], poses[rows, link, :3, 3])
    x = _apply(back, centers) + shift  # in the link's home frame
    planes = hulls.planes[link]
    s = (x[:, None] @ planes[..., :3].swapaxes(-1, -2))[:, 0] + planes[..., 3]  # (k, K)
    top = s.argmax(axis=1)
    out = s[np.arange(len(x)), top]  # the distance where the centre is inside or over a face
    foot = x - out[:, None] * planes[np.arange(len(x)), top, :3]
    over_face = (out <= 0) | (hull_depth(foot, planes) >= -1e-9 * (1 + np.abs(out)))
    nearest = _length(hulls.vertices[link] - x[:, None]).min(axis=1)
    return radii - np.where(over_face, out, nearest)
