r"""A closed triangle mesh in its own frame: nearest points, volume and centroid, sampling.

The mesh is a :class:`~grasptwist.model.Shape` of kind ``"mesh"`` accepted by
:func:`~.checks.check_shape`: closed, faces counter-clockwise seen from
outside.  What is derived from it once (face normals and areas, the normals
at edges and vertices, the search tree) is kept while the shape lives.

Nearest points
--------------
The nearest point :math:`c` of a triangle mesh to :math:`q` lies in the
triangle that the search tree finds (libigl's axis-aligned bounding-box tree,
:func:`igl.AABB`, exact; the ``mesh`` extra).  Its barycentric coordinates
:math:`\lambda_i` give how far it is from each edge, :math:`\lambda_i h_i`
(:math:`h_i` the triangle's height over edge :math:`i`); within
:data:`~.tolerances.MESH_EDGE_TOL` of the object's size it is on that edge,
and on two edges on their vertex.  The outward normal is the face's inside a
face, and at an edge or a vertex the area-weighted normal of the faces that
meet there,

.. math::

    n = \frac{\sum_f A_f n_f}{\left|\sum_f A_f n_f\right|}.

The sign of the distance (inside or outside) is that of :math:`(q - c)\cdot N`
with :math:`N` the angle-weighted pseudo-normal of the same face, edge or
vertex (Baerentzen and Aanaes 2005: exact for a closed mesh, where an
area-weighted normal is not always).
"""

from __future__ import annotations

import weakref

import numpy as np

from ...extras import require
from ...model import Shape
from .tolerances import MESH_EDGE_TOL

__all__ = ["diagonal", "volume_centroid", "sample", "nearest"]


def diagonal(vertices) -> float:
    """The diagonal of the vertices' axis-aligned bounding box.

    >>> diagonal(np.array([[0.0, 0, 0], [3, 4, 12]]))
    13.0
    """
    return float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))


def _corners(shape):
    v = shape.vertices
    f = shape.faces
    return v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]


def volume_centroid(shape: Shape) -> tuple[float, np.ndarray]:
    r"""The volume a closed mesh encloses and its centroid (a uniform solid's centre of mass).

    Each face and the origin make a tetrahedron of signed volume
    :math:`V_f = a \cdot (b \times c) / 6` and centroid :math:`(a + b + c) / 4`;
    summed over the faces of a closed surface, the parts outside cancel:

    .. math::

        V = \sum_f V_f, \qquad c = \frac{1}{V} \sum_f V_f\, \frac{a_f + b_f + c_f}{4}

    >>> from grasptwist.engine.objects.primitives import triangles
    >>> v, f = triangles("box", [1.0, 2.0, 3.0], 0)
    >>> volume, centroid = volume_centroid(Shape("mesh", np.zeros(0), v + 1, f))
    >>> round(volume, 12), centroid.round(12).tolist()
    (6.0, [1.0, 1.0, 1.0])
    """
    a, b, c = _corners(shape)
    # about the bounding box's centre: the cancelling tetrahedra stay small
    origin = 0.5 * (shape.vertices.max(axis=0) + shape.vertices.min(axis=0))
    a, b, c = a - origin, b - origin, c - origin
    parts = np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0
    volume = float(parts.sum())
    return volume, (parts @ (a + b + c)) / (4.0 * volume) + origin


def sample(shape: Shape, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    r"""``n`` points uniformly distributed over the mesh (by area) and the outward normals of their faces.

    A face is drawn with probability proportional to its area, then a point
    of it from two uniform numbers :math:`u, v`:
    :math:`(1 - \sqrt u)\, a + \sqrt u (1 - v)\, b + \sqrt u\, v\, c`
    (uniform over the triangle).

    >>> from grasptwist.engine.objects.primitives import triangles
    >>> v, f = triangles("box", [2.0, 2.0, 2.0], 0)
    >>> p, n = sample(Shape("mesh", np.zeros(0), v, f), 5, np.random.default_rng(0))
    >>> bool(np.allclose(np.abs(p).max(axis=1), 1.0)), bool(np.allclose((p * n).sum(axis=1), 1.0))
    (True, True)
    """
    d = _derived(shape)
    face = rng.choice(len(d.areas), size=n, p=d.areas / d.areas.sum())
    u, v = rng.random((2, n))
    r = np.sqrt(u)[:, None]
    a, b, c = (x[face] for x in _corners(shape))
    return (1 - r) * a + r * (1 - v[:, None]) * b + r * v[:, None] * c, d.face_normals[face]


class _Derived:
    """What a mesh's queries need, computed once per shape."""

    def __init__(self, shape: Shape):
        v, f = shape.vertices, shape.faces
        a, b, c = _corners(shape)
        cross = np.cross(b - a, c - a)
        twice = np.linalg.norm(cross, axis=1)
        self.areas = 0.5 * twice
        with np.errstate(invalid="ignore", divide="ignore"):
            self.face_normals = np.nan_to_num(cross / twice[:, None])
        edges = np.stack([c - b, a - c, b - a], axis=1)  # edge i faces vertex i
        lengths = np.linalg.norm(edges, axis=2)
        with np.errstate(invalid="ignore", divide="ignore"):
            self.heights = np.where(lengths > 0, twice[:, None] / lengths, 0.0)  # over edge i
        weighted = cross  # = 2 A_f n_f
        self.vertex_normals = _unit(_accumulate(len(v), f, weighted))
        # angles at each corner, for the pseudo-normals
        angles = np.stack(
            [_angle(-edges[:, 2], edges[:, 1]), _angle(-edges[:, 0], edges[:, 2]), _angle(-edges[:, 1], edges[:, 0])],
            axis=1,
        )
        self.vertex_pseudo = _accumulate(len(v), f, self.face_normals, angles)
        # the edge of each face's side i (opposite vertex i), and its partner face
        n = len(v)
        lo = np.minimum(f[:, [1, 2, 0]], f[:, [2, 0, 1]])
        hi = np.maximum(f[:, [1, 2, 0]], f[:, [2, 0, 1]])
        key = (lo * n + hi).reshape(-1)
        order = np.argsort(key, kind="stable")
        # closed and manifold: every edge key appears exactly twice, once in each of its faces
        pair = np.empty_like(order)
        pair[order[0::2]] = order[1::2]
        pair[order[1::2]] = order[0::2]
        other = (pair // 3).reshape(-1, 3)
        mine = np.repeat(np.arange(len(f)), 3).reshape(-1, 3)
        self.partner = other  # (F, 3): the face across each side (creases.py's dihedral angles)
        self.edge_normals = _unit(weighted[mine] + weighted[other])
        self.edge_pseudo = self.face_normals[mine] + self.face_normals[other]
        self.tol = MESH_EDGE_TOL * diagonal(v)
        self.vertices = np.ascontiguousarray(v, dtype=float)
        self.faces = np.ascontiguousarray(f, dtype=np.int64)
        self._tree = None

    def nearest_faces(self, q):
        """libigl's answer for the points ``q (N, 3)``: the nearest face of each and the nearest point on it."""
        if self._tree is None:  # the first query builds the tree: sampling and volumes need no libigl
            igl = require("igl", "a mesh object's nearest points")  # optional (the mesh extra): imported when used
            self._tree = igl.AABB()
            self._tree.init(self.vertices, self.faces)
        _, face, c = self._tree.squared_distance(self.vertices, self.faces, np.ascontiguousarray(q, dtype=float))
        return face, c


def _angle(u, v):
    return np.arctan2(np.linalg.norm(np.cross(u, v), axis=-1), np.einsum("ij,ij->i", u, v))


def _accumulate(n, faces, values, weights=None):
    """Per vertex, the sum of its faces' ``values`` (times the corner's ``weights``)."""
    out = np.zeros((n, 3))
    for i in range(3):
        w = values if weights is None else values * weights[:, i : i + 1]
        np.add.at(out, faces[:, i], w)
    return out


def _unit(v):
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(length > 0, v / length, 0.0)


_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _derived(shape: Shape) -> _Derived:
    d = _CACHE.get(shape)
    if d is None:
        d = _CACHE[shape] = _Derived(shape)
    return d


def nearest(shape: Shape, q: np.ndarray):
    """Nearest surface point, outward unit normal, signed distance (> 0 outside) and edge flag of each point ``q (N, 3)``.

    Returns
    -------
    point, normal : numpy.ndarray
        Shape ``(N, 3)`` each.
    distance : numpy.ndarray
        Shape ``(N,)``.
    on_edge : numpy.ndarray
        Shape ``(N,)`` bool: the nearest point is within ``MESH_EDGE_TOL`` of the size of an edge
        or vertex (one between coplanar faces too), where the normal is the faces' average.

    >>> from grasptwist.engine.objects.primitives import triangles
    >>> v, f = triangles("box", [2.0, 2.0, 2.0], 0)
    >>> c, n, d, on_edge = nearest(Shape("mesh", np.zeros(0), v, f), np.array([[0.0, 0, 3], [2, 2, 2], [0.5, 0.2, 0]]))
    >>> c.round(12).tolist(), d.round(4).tolist()
    ([[0.0, 0.0, 1.0], [1.0, 1.0, 1.0], [1.0, 0.2, 0.0]], [2.0, 1.7321, -0.5])
    >>> n.round(4).tolist(), on_edge.tolist()
    ([[0.0, 0.0, 1.0], [0.5774, 0.5774, 0.5774], [1.0, 0.0, 0.0]], [True, True, False])
    """
    d = _derived(shape)
    if len(q) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0), np.zeros(0, dtype=bool)
    face, c = d.nearest_faces(q)
    lam = _barycentric(shape, face, c)
    near_edge = lam * d.heights[face] <= d.tol  # (N, 3): on the edge opposite vertex i
    count = near_edge.sum(axis=1)
    normal = d.face_normals[face]
    pseudo = normal.copy()
    # on one edge: its faces' normals
    edge = count == 1
    side = np.argmax(near_edge, axis=1)
    normal[edge] = d.edge_normals[face[edge], side[edge]]
    pseudo[edge] = d.edge_pseudo[face[edge], side[edge]]
    # on two edges: the vertex between them (the one whose coordinate is not near 0)
    corner = count >= 2
    vertex = shape.faces[face, np.argmax(np.where(near_edge, -np.inf, lam), axis=1)]
    vertex = np.where(count == 3, shape.faces[face, np.argmax(lam, axis=1)], vertex)
    normal[corner] = d.vertex_normals[vertex[corner]]
    pseudo[corner] = d.vertex_pseudo[vertex[corner]]
    away = q - c
    distance = np.linalg.norm(away, axis=1)
    inside = np.einsum("ij,ij->i", away, pseudo) < 0
    return c, normal, np.where(inside, -distance, distance), count >= 1


def _barycentric(shape, face, c):
    """Barycentric coordinates ``(N, 3)`` of the points ``c`` in the triangles ``face``."""
    v, f = shape.vertices, shape.faces[face]
    a, b, cc = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    e0, e1, e2 = b - a, cc - a, c - a
    d00 = np.einsum("ij,ij->i", e0, e0)
    d01 = np.einsum("ij,ij->i", e0, e1)
    d11 = np.einsum("ij,ij->i", e1, e1)
    d20 = np.einsum("ij,ij->i", e2, e0)
    d21 = np.einsum("ij,ij->i", e2, e1)
    det = d00 * d11 - d01 * d01
    with np.errstate(invalid="ignore", divide="ignore"):
        l1 = (d11 * d20 - d01 * d21) / det
        l2 = (d00 * d21 - d01 * d20) / det
    lam = np.stack([1 - l1 - l2, l1, l2], axis=1)
    return np.nan_to_num(np.clip(lam, 0.0, 1.0))
