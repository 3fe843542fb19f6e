r"""The four primitives in their own frame, exactly: nearest points, volumes, sampling, triangles.

Every primitive is centred at its frame's origin, its axis (cylinder,
capsule) along z.  Functions take the shape's ``size`` (as
:class:`~grasptwist.model.Shape` holds it) and points ``q`` of shape
``(N, 3)`` in the object's frame, and return *outward* unit vectors: the
object-level functions (:mod:`.geometry`) move them to the grasp frame and
turn them inward.

Nearest points
--------------
A box of half edges ``h`` is the set ``|q_i| <= h_i``.  Outside, its nearest
point clamps each coordinate, :math:`c_i = \operatorname{sign}(q_i)\min(|q_i|, h_i)`,
at the distance :math:`|q - c|` along :math:`(q - c)/|q - c|` (a face's
normal in front of a face, the direction from the edge or corner beside
one).  Inside, it is on the nearest face, the axis :math:`k` of the least
:math:`h_k - |q_k|`, at the signed distance :math:`-(h_k - |q_k|)`.  A
cylinder is the same rectangle in the half-plane of :math:`(\rho, z)`,
:math:`\rho = \sqrt{x^2 + y^2}`, with half edges ``(radius, height / 2)``; a
sphere and a capsule are the points within ``radius`` of a segment (of
length 0 for the sphere) on the z axis:

.. math::

    c = a + r\,\frac{q - a}{|q - a|}, \qquad d = |q - a| - r, \qquad
    a = (0, 0, \operatorname{clip}(q_z, -h, h)).

Where the nearest point is not unique or the normal not defined, the answer
is fixed and documented: a point on an edge, corner or rim (within
:data:`~.tolerances.EDGE_TOL` of the object's size) takes the bisector of
the faces that meet there; a point as far from two faces inside a box or a
cylinder goes to the first (x before y before z; a cylinder's side before
its caps; the positive face before the negative); a point on the axis of a
cylinder or capsule, or at a sphere's centre, goes to the ``+x`` side.  No
finite input gives NaN.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "PRIMITIVES",
    "second_moment",
    "nearest",
    "nearest_one",
    "signed_distance",
    "volume",
    "diagonal",
    "sample",
    "triangles",
]

#: The primitive kinds and how many numbers their ``size`` holds.
PRIMITIVES = {"box": 3, "sphere": 1, "cylinder": 2, "capsule": 2}

_X = np.array([1.0, 0.0, 0.0])


def _norm(v):
    return np.sqrt(np.einsum("...i,...i->...", v, v))


def _nearest_on_box(q, half, tol):
    """Nearest point, outward unit normal, signed distance and whether the point is on an edge or corner
    (within ``tol`` of two faces) of ``q (N, k)`` to the box ``|q_i| <= half_i``."""
    sign = np.where(q < 0, -1.0, 1.0)
    gap = half - np.abs(q)  # > 0: inside along that axis
    out = np.maximum(-gap, 0.0)
    outside = _norm(out)
    inside = (outside == 0)[:, None]
    nearest_face = np.arange(q.shape[-1]) == np.argmin(gap, axis=-1)[:, None]  # ties: the first axis
    distance = np.where(outside > 0, outside, -np.min(gap, axis=-1)) + 0.0  # + 0.0: no -0.0 on the surface
    point = np.where(inside & nearest_face, sign * half, sign * np.minimum(np.abs(q), half))
    with np.errstate(invalid="ignore", divide="ignore"):
        away = sign * out / outside[:, None]
    normal = np.where(inside, sign * nearest_face, away)
    # On the surface (an edge, a corner, a rim included): the faces it lies on, bisected.
    on = (np.abs(distance) <= tol)[:, None]
    normal = np.where(on, sign * (gap <= tol), normal)
    normal /= _norm(normal)[:, None]
    edge = ((half - np.abs(point)) <= tol).sum(axis=-1) >= 2  # the nearest point on two faces or more
    return point, normal, distance, edge


def _radial(q):
    """``(rho, unit radial direction)`` of ``q (N, 3)`` about the z axis; ``+x`` on the axis."""
    rho = np.hypot(q[:, 0], q[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.where((rho > 0)[:, None], q[:, :2] / rho[:, None], _X[:2])
    return rho, u


def _box(size, q, tol):
    return _nearest_on_box(q, 0.5 * size, tol)


def _cylinder(size, q, tol):
    rho, u = _radial(q)
    half = np.array([size[0], 0.5 * size[1]])
    point, normal, distance, rim = _nearest_on_box(np.stack([rho, q[:, 2]], axis=-1), half, tol)
    return _lift(point, u), _lift(normal, u), distance, rim


def _lift(rz, u):
    """``(rho, z)`` pairs back to 3D along the radial directions ``u``."""
    return np.concatenate([rz[:, :1] * u, rz[:, 1:]], axis=-1)


def _capsule(size, q, tol):
    return _round(size[0], 0.5 * size[1], q)


def _sphere(size, q, tol):
    return _round(size[0], 0.0, q)


def _round(radius, half, q):
    """Points within ``radius`` of the segment ``z`` in ``[-half, half]`` of the z axis."""
    axis = np.zeros_like(q)
    axis[:, 2] = np.clip(q[:, 2], -half, half)
    v = q - axis
    length = _norm(v)
    with np.errstate(invalid="ignore", divide="ignore"):
        normal = np.where((length > 0)[:, None], v / length[:, None], _X)
    return axis + radius * normal, normal, length - radius, np.zeros(len(q), dtype=bool)  # smooth: no edge


_NEAREST = {"box": _box, "sphere": _sphere, "cylinder": _cylinder, "capsule": _capsule}


def nearest(kind, size, q, tol):
    """Nearest surface point, outward unit normal, signed distance (> 0 outside) and edge flag of each point.

    Parameters
    ----------
    kind : str
        A key of :data:`PRIMITIVES`.
    size : numpy.ndarray
        The primitive's sizes, shape ``(PRIMITIVES[kind],)``.
    q : numpy.ndarray
        Points in the primitive's frame, shape ``(N, 3)``.
    tol : float
        Distance within which a point is on an edge, corner or rim (and on
        the surface): its normal is then the bisector of the faces there.

    Returns
    -------
    point, normal : numpy.ndarray
        Shape ``(N, 3)`` each.
    distance : numpy.ndarray
        Shape ``(N,)``, > 0 outside.
    on_edge : numpy.ndarray
        Shape ``(N,)`` bool: the nearest point is within ``tol`` of a box's edge or corner or
        of a cylinder's rim (never on a sphere or capsule, which are smooth).

    Examples
    --------
    A unit cube's corner region, an edge and a face's inside:

    >>> c, n, d, on_edge = nearest("box", np.ones(3), np.array([[1.0, 1, 1], [0.5, 0.5, 0], [0.25, 0, 0]]), 1e-12)
    >>> c.tolist(), d.round(4).tolist()
    ([[0.5, 0.5, 0.5], [0.5, 0.5, 0.0], [0.5, 0.0, 0.0]], [0.866, 0.0, -0.25])
    >>> n.round(4).tolist(), on_edge.tolist()
    ([[0.5774, 0.5774, 0.5774], [0.7071, 0.7071, 0.0], [1.0, 0.0, 0.0]], [True, True, False])
    """
    return _NEAREST[kind](np.asarray(size, dtype=float), q, tol)


def _box_distance(half, q):
    """``nearest``'s distance for the box ``|q_i| <= half_i`` alone: ``(N, k) -> (N,)``."""
    gap = np.abs(q) - half  # > 0: outside along that axis
    outside = _norm(np.maximum(gap, 0.0))
    deepest = gap[..., 0]
    for k in range(1, gap.shape[-1]):  # the largest gap, column by column: a reduction over a short
        deepest = np.maximum(deepest, gap[..., k])  # last axis is numpy's slowest path (collision tests' inner loop)
    return np.where(outside > 0, outside, deepest) + 0.0


def _round_distance(radius, half, q):
    """``nearest``'s distance for the points within ``radius`` of the z axis' segment ``[-half, half]``."""
    axis = np.zeros_like(q)
    axis[:, 2] = np.clip(q[:, 2], -half, half)
    return _norm(q - axis) - radius


_DISTANCE = {
    "box": lambda size, q: _box_distance(0.5 * size, q),
    "cylinder": lambda size, q: _box_distance(
        np.array([size[0], 0.5 * size[1]]), np.stack([np.hypot(q[:, 0], q[:, 1]), q[:, 2]], axis=-1)
    ),
    "sphere": lambda size, q: _round_distance(size[0], 0.0, q),
    "capsule": lambda size, q: _round_distance(size[0], 0.5 * size[1], q),
}


def signed_distance(kind, size, q):
    """:func:`nearest`'s signed distance alone (> 0 outside), the same numbers, without the points,
    normals and edges (a collision test's query, over many points): ``(N, 3) -> (N,)``.

    >>> signed_distance("box", np.ones(3), np.array([[1.0, 1, 1], [0.5, 0.5, 0], [0.25, 0, 0]])).round(4).tolist()
    [0.866, 0.0, -0.25]
    """
    return _DISTANCE[kind](np.asarray(size, dtype=float), q)


def nearest_one(kind, size, q):
    """One point's nearest point, outward normal and signed distance in Python floats: :func:`nearest`'s readable twin.

    The same formulas, one point at a time, without the edge tolerance (a
    point exactly on an edge takes one face's normal here); the tests and
    ``bench/objects.py`` hold the vectorised :func:`nearest` to it.

    >>> nearest_one("cylinder", [1.0, 2.0], (0.0, 3.0, 0.5))
    ((0.0, 1.0, 0.5), (0.0, 1.0, 0.0), 2.0)
    """
    x, y, z = q
    if kind in ("sphere", "capsule"):
        half = 0.0 if kind == "sphere" else size[1] / 2
        az = min(max(z, -half), half)
        vx, vy, vz = x, y, z - az
        length = math.sqrt(vx * vx + vy * vy + vz * vz)
        n = (vx / length, vy / length, vz / length) if length > 0 else (1.0, 0.0, 0.0)
        r = size[0]
        return (r * n[0], r * n[1], az + r * n[2]), n, length - r
    if kind == "box":
        coords, half = [x, y, z], [s / 2 for s in size]
    else:  # a cylinder is a rectangle in (rho, z)
        rho = math.hypot(x, y)
        coords, half = [rho, z], [size[0], size[1] / 2]
    sign = [-1.0 if c < 0 else 1.0 for c in coords]
    gap = [h - abs(c) for h, c in zip(half, coords)]
    out = [max(-g, 0.0) for g in gap]
    outside = math.sqrt(sum(o * o for o in out))
    point = [s * min(abs(c), h) for s, c, h in zip(sign, coords, half)]
    if outside > 0:
        normal, distance = [s * o / outside for s, o in zip(sign, out)], outside
    else:
        k = gap.index(min(gap))
        point[k] = sign[k] * half[k]
        normal = [0.0] * len(coords)
        normal[k] = sign[k]
        distance = -gap[k]
    if kind == "box":
        return tuple(point), tuple(normal), distance
    ux, uy = (x / rho, y / rho) if rho > 0 else (1.0, 0.0)
    return (point[0] * ux, point[0] * uy, point[1]), (normal[0] * ux, normal[0] * uy, normal[1]), distance


def volume(kind, size) -> float:
    r"""The primitive's volume.

    .. math::

        V_\text{box} = abc, \quad V_\text{sphere} = \tfrac43 \pi r^3, \quad
        V_\text{cylinder} = \pi r^2 h, \quad V_\text{capsule} = \pi r^2 h + \tfrac43 \pi r^3

    >>> round(volume("capsule", [1.0, 2.0]), 4)  # 2 pi + 4/3 pi
    10.472
    """
    s = [float(x) for x in size]
    if kind == "box":
        return s[0] * s[1] * s[2]
    ball = 4.0 / 3.0 * math.pi * s[0] ** 3
    if kind == "sphere":
        return ball
    tube = math.pi * s[0] ** 2 * s[1]
    return tube if kind == "cylinder" else tube + ball


def second_moment(kind, size) -> np.ndarray:
    r"""The primitive's second moment of volume about its centre, :math:`J = \int x x^T dV` ``(3, 3)`` (diagonal).

    .. math::

        J_\text{box} = \tfrac{V}{12}\operatorname{diag}(a^2, b^2, c^2), \quad
        J_\text{sphere} = \tfrac{V r^2}{5} I, \quad
        J_\text{cylinder} = V \operatorname{diag}\left(\tfrac{r^2}{4}, \tfrac{r^2}{4}, \tfrac{h^2}{12}\right)

    and a capsule its cylinder's plus its two half balls' (volume :math:`V_b` together, each's
    centroid :math:`3r/8` beyond its flat face at :math:`\pm h/2`):
    :math:`J_{zz} = V_b\,(h^2/4 + 3rh/8 + r^2/5)`, :math:`J_{xx} = J_{yy} = V_b r^2/5`.
    A uniform body of mass :math:`m` has the inertia tensor
    :math:`\frac{m}{V}(\operatorname{tr}(J) I - J)` about its centre.

    >>> np.diag(second_moment("box", [1.0, 2.0, 3.0])).tolist()
    [0.5, 2.0, 4.5]
    """
    s = [float(x) for x in size]
    v = volume(kind, s)
    if kind == "box":
        return np.diag([v * x * x / 12.0 for x in s])
    r = s[0]
    if kind == "sphere":
        return np.eye(3) * v * r * r / 5.0
    tube = math.pi * r * r * s[1]
    h = s[1]
    j = tube * np.diag([r * r / 4.0, r * r / 4.0, h * h / 12.0])
    if kind == "capsule":
        ball = v - tube
        j += ball * np.diag([r * r / 5.0, r * r / 5.0, h * h / 4.0 + 3.0 * r * h / 8.0 + r * r / 5.0])
    return j


def diagonal(kind, size) -> float:
    """The diagonal of the primitive's bounding box in its own frame.

    >>> diagonal("box", [3, 4, 12]), round(diagonal("sphere", [1]), 4)
    (13.0, 3.4641)
    """
    s = [float(x) for x in size]
    if kind == "box":
        edges = s
    elif kind == "sphere":
        edges = [2 * s[0]] * 3
    else:
        cap = 2 * s[0] if kind == "capsule" else 0.0
        edges = [2 * s[0], 2 * s[0], s[1] + cap]
    return math.sqrt(sum(e * e for e in edges))


def _areas(kind, size):
    """The areas of the primitive's parts, in :func:`_on_part`'s order."""
    s = [float(x) for x in size]
    if kind == "box":
        a, b, c = s
        return np.repeat([b * c, a * c, a * b], 2)  # +x, -x, +y, -y, +z, -z
    if kind == "sphere":
        return np.array([4 * math.pi * s[0] ** 2])
    side = 2 * math.pi * s[0] * s[1]
    if kind == "cylinder":
        return np.array([side, math.pi * s[0] ** 2, math.pi * s[0] ** 2])  # side, top, bottom
    return np.array([side, 4 * math.pi * s[0] ** 2])  # side, the two caps together


def sample(kind, size, n, rng):
    r"""``n`` points uniformly distributed over the primitive's surface (by area) and their outward normals.

    One part (a face, the side, a cap) is drawn for each point with
    probability proportional to its area, then three uniform numbers
    :math:`u, v, w \in [0, 1)` place it: on a face at
    :math:`(u - \tfrac12) a`, ...; on a side at angle :math:`2\pi u` and
    height :math:`(v - \tfrac12) h`; on a disc at radius :math:`r\sqrt{v}`
    (uniform in area); on a sphere at :math:`z = r(2w - 1)` (Archimedes: the
    height of a uniform point on a sphere is uniform).  The draws are the same
    for every kind, so a generator's state gives the same points every time.

    Returns
    -------
    points, normals : numpy.ndarray
        Shape ``(n, 3)`` each, in the primitive's frame; the normals outward.

    >>> p, n = sample("sphere", [2.0], 4, np.random.default_rng(0))
    >>> np.allclose(np.linalg.norm(p, axis=1), 2) and np.allclose(p, 2 * n)
    True
    """
    s = np.asarray(size, dtype=float)
    areas = _areas(kind, s)
    part = rng.choice(len(areas), size=n, p=areas / areas.sum())
    u, v, w = rng.random((3, n))
    return _on_part(kind, s, part, u, v, w)


def _on_part(kind, s, part, u, v, w):
    n = len(part)
    if kind == "box":
        axis = part // 2
        sign = np.where(part % 2 == 0, 1.0, -1.0)
        points = (np.stack([u, v, w], axis=-1) - 0.5) * s
        rows = np.arange(n)
        points[rows, axis] = sign * 0.5 * s[axis]
        normals = np.zeros((n, 3))
        normals[rows, axis] = sign
        return points, normals
    radius = s[0]
    angle = 2 * math.pi * u
    if kind == "sphere" or kind == "capsule":
        z = 2 * w - 1
        ring = np.sqrt(np.maximum(1 - z * z, 0.0))
        normals = np.stack([ring * np.cos(angle), ring * np.sin(angle), z], axis=-1)
        points = radius * normals
        if kind == "sphere":
            return points, normals
        points[:, 2] += np.where(z >= 0, 0.5, -0.5) * s[1]
        side = part == 0
    else:  # cylinder: side, top, bottom
        side = part == 0
        top = np.where(part == 1, 1.0, -1.0)
        disc = radius * np.sqrt(v)
        points = np.stack([disc * np.cos(angle), disc * np.sin(angle), 0.5 * s[1] * top], axis=-1)
        normals = np.zeros((n, 3))
        normals[:, 2] = top
    radial = np.stack([np.cos(angle), np.sin(angle), np.zeros(n)], axis=-1)
    along = np.stack([radius * radial[:, 0], radius * radial[:, 1], (v - 0.5) * s[1]], axis=-1)
    points[side] = along[side]
    normals[side] = radial[side]
    return points, normals


#: A box's corners (x, y, z signs) and its triangles, counter-clockwise seen from outside.
_BOX_CORNERS = np.array(
    [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float
)
_BOX_FACES = np.array(
    [
        [0, 3, 2], [0, 2, 1],  # -z
        [4, 5, 6], [4, 6, 7],  # +z
        [0, 1, 5], [0, 5, 4],  # -y
        [3, 7, 6], [3, 6, 2],  # +y
        [1, 2, 6], [1, 6, 5],  # +x
        [0, 4, 7], [0, 7, 3],  # -x
    ]
)  # fmt: skip


def triangles(kind, size, segments):
    """A closed triangle mesh of the primitive, faces counter-clockwise seen from outside.

    A box is its 12 triangles; the round primitives are surfaces of
    revolution with ``segments`` vertices per ring (their vertices on the exact
    surface, so the mesh lies inside it): a sphere has ``segments // 2``
    bands of latitude, a capsule ``segments // 4`` per cap, a cylinder one band
    and two flat caps.

    Returns
    -------
    vertices : numpy.ndarray
        Shape ``(V, 3)``.
    faces : numpy.ndarray
        Shape ``(F, 3)``, int.

    >>> v, f = triangles("cylinder", [1.0, 2.0], 8)
    >>> v.shape, f.shape
    ((18, 3), (32, 3))
    """
    s = [float(x) for x in size]
    if kind == "box":
        return 0.5 * _BOX_CORNERS * np.asarray(s), _BOX_FACES.copy()
    radius = s[0]
    if kind == "cylinder":
        half = 0.5 * s[1]
        profile = [(0.0, -half), (radius, -half), (radius, half), (0.0, half)]
    else:
        bands = max(segments // 2, 2) if kind == "sphere" else 2 * max(segments // 4, 1)
        half = 0.0 if kind == "sphere" else 0.5 * s[1]
        latitude = np.linspace(-0.5 * math.pi, 0.5 * math.pi, bands + 1)
        rho, z = radius * np.cos(latitude), radius * np.sin(latitude)
        rho[[0, -1]] = 0.0  # the poles, exactly on the axis
        if kind == "sphere":
            profile = list(zip(rho, z))
        else:  # the equator twice, at the ends of the tube
            m = bands // 2
            profile = [(r, h - half) for r, h in zip(rho[: m + 1], z[: m + 1])]
            profile += [(r, h + half) for r, h in zip(rho[m:], z[m:])]
    return _lathe(np.array(profile), max(segments, 3))


def _lathe(profile, segments):
    """The surface swept by a ``(rho, z)`` profile from the bottom pole to the top pole about the z axis."""
    rings = profile[1:-1]
    m = len(rings)
    angle = 2 * math.pi * np.arange(segments) / segments
    ring_points = np.stack(
        [
            rings[:, :1] * np.cos(angle),
            rings[:, :1] * np.sin(angle),
            np.broadcast_to(rings[:, 1:], (m, segments)),
        ],
        axis=-1,
    ).reshape(-1, 3)
    bottom, top = 0, 1 + m * segments
    vertices = np.concatenate([[[0.0, 0.0, profile[0, 1]]], ring_points, [[0.0, 0.0, profile[-1, 1]]]])
    j = np.arange(segments)
    nxt = (j + 1) % segments
    faces = [np.stack([np.full(segments, bottom), 1 + nxt, 1 + j], axis=-1)]
    for i in range(m - 1):
        a, b = 1 + i * segments + j, 1 + i * segments + nxt
        c, d = b + segments, a + segments
        faces += [np.stack([a, b, c], axis=-1), np.stack([a, c, d], axis=-1)]
    last = 1 + (m - 1) * segments
    faces.append(np.stack([last + j, last + nxt, np.full(segments, top)], axis=-1))
    return vertices, np.concatenate(faces)
