r"""A triangle mesh in its own frame: nearest points, mass properties, sampling, on the solid it bounds.

The mesh is a :class:`~grasptwist.model.Shape` of kind ``"mesh"`` accepted by
:func:`~.checks.check_shape` (repaired: no zero-area face).  Its solid, the points where its
generalized winding number is above 1/2, and the outer surface that bounds it
(:mod:`~.solid`) are found once and kept while the shape lives, with what the
queries derive from them (face normals and areas, the normals at edges and
vertices, the search tree).  Every query is on the outer surface: a face inside
another piece, or round a cavity, holds no nearest point and no sample.

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
vertex (Baerentzen and Aanaes 2005: exact for a closed surface, where an
area-weighted normal is not always); where the outer surface is open (a hole's
rim, where a face is split along another piece), the winding number's
(inside where it is above 1/2).
"""

from __future__ import annotations

import atexit
import weakref

import numpy as np

from ...extras import require
from ...model import Shape
from .solid import _distance, moments, solid, surface_moments, winding_function
from .tolerances import MESH_EDGE_TOL

__all__ = ["diagonal", "mass_moments", "solid_of", "sample", "body_areas", "body_of", "face_distance", "nearest"]


def diagonal(vertices) -> float:
    """The diagonal of the vertices' axis-aligned bounding box.

    >>> diagonal(np.array([[0.0, 0, 0], [3, 4, 12]]))
    13.0
    """
    return float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))


def solid_of(shape: Shape):
    """The :class:`~.solid.Solid` of the mesh (its outer surface, bodies, what was found), kept with the shape."""
    return _derived(shape).solid


def mass_moments(shape: Shape) -> tuple[float, np.ndarray, np.ndarray]:
    r"""The volume of the mesh's solid, its centroid ``(3,)`` and its second moment about the centroid ``(3, 3)``.

    .. math::

        V = \int_S dV, \qquad c = \frac{1}{V}\int_S x\, dV, \qquad
        J = \int_S (x - c)(x - c)^T dV

    By the divergence theorem when the mesh is one closed surface
    (:func:`~.solid.surface_moments`, needs no libigl), else along rays through the solid
    (:func:`~.solid.moments`: counting the crossings where each piece is closed, by the winding
    number where the mesh is open).  A uniform solid of density :math:`\rho` has its inertia
    tensor :math:`\rho\,(\operatorname{tr}(J) I - J)` about :math:`c`.

    >>> from grasptwist.engine.objects.primitives import triangles
    >>> v, f = triangles("box", [1.0, 2.0, 3.0], 0)
    >>> volume, centroid, second = mass_moments(Shape("mesh", np.zeros(0), v + 1, f))
    >>> round(volume, 12), centroid.round(12).tolist(), np.diag(second).round(12).tolist()
    (6.0, [1.0, 1.0, 1.0], [0.5, 2.0, 4.5])
    """
    d = _derived(shape)
    if d.moments is None:  # kept with the shape: the rays through an open mesh take a while
        s = d.solid
        volume, first, second = surface_moments(*s.source) if s.closed else moments(s.source, closed=not s.open_edges)
        centroid = first / volume
        d.moments = volume, centroid, second - volume * np.outer(centroid, centroid)
    volume, centroid, second = d.moments
    return volume, centroid.copy(), second.copy()


def sample(shape: Shape, n: int, rng: np.random.Generator, *, body=None) -> tuple[np.ndarray, np.ndarray]:
    r"""``n`` points uniformly distributed over the solid's outer surface (by area) and the outward normals of their faces.

    A face is drawn with probability proportional to its area, then a point
    of it from two uniform numbers :math:`u, v`:
    :math:`(1 - \sqrt u)\, a + \sqrt u (1 - v)\, b + \sqrt u\, v\, c`
    (uniform over the triangle).  ``body``: only that body's faces (:attr:`~.solid.Solid.body`).

    >>> from grasptwist.engine.objects.primitives import triangles
    >>> v, f = triangles("box", [2.0, 2.0, 2.0], 0)
    >>> p, n = sample(Shape("mesh", np.zeros(0), v, f), 5, np.random.default_rng(0))
    >>> bool(np.allclose(np.abs(p).max(axis=1), 1.0)), bool(np.allclose((p * n).sum(axis=1), 1.0))
    (True, True)
    """
    d = _derived(shape)
    weight = d.areas if body is None else np.where(d.solid.body == body, d.areas, 0.0)
    face = rng.choice(len(weight), size=n, p=weight / weight.sum())
    u, v = rng.random((2, n))
    r = np.sqrt(u)[:, None]
    a, b, c = (x[face] for x in d.corners)
    return (1 - r) * a + r * (1 - v[:, None]) * b + r * v[:, None] * c, d.face_normals[face]


def body_areas(shape: Shape) -> np.ndarray:
    """The area of each body's outer surface: ``(bodies,)``."""
    d = _derived(shape)
    return np.bincount(d.solid.body, weights=d.areas, minlength=d.solid.bodies)


def body_of(shape: Shape, q: np.ndarray) -> np.ndarray:
    """The body whose outer surface is nearest each point ``q (N, 3)``: ``(N,)`` int."""
    d = _derived(shape)
    if len(q) == 0:
        return np.zeros(0, dtype=np.int64)
    return d.solid.body[d.nearest_faces(q)[0]]


def face_distance(shape: Shape, q: np.ndarray) -> np.ndarray:
    """Each point's distance ``(N,)`` to the nearest face of the mesh as given (internal ones and cavities too)."""
    return _distance(shape.vertices, shape.faces, q) if len(q) else np.zeros(0)


class _Derived:
    """What a mesh's queries need, computed once per shape."""

    def __init__(self, shape: Shape):
        self.solid = s = solid(shape.vertices, shape.faces)
        v, f = s.vertices, s.faces
        self.corners = a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
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
        # the edge of each face's side i (opposite vertex i) and its partner face: the other face of an edge
        # in two, the face itself on an open edge (or one in more than two: there the winding number decides)
        n = len(v)
        lo = np.minimum(f[:, [1, 2, 0]], f[:, [2, 0, 1]])
        hi = np.maximum(f[:, [1, 2, 0]], f[:, [2, 0, 1]])
        key = (lo * n + hi).reshape(-1)
        order = np.argsort(key, kind="stable")
        _, start, count = np.unique(key[order], return_index=True, return_counts=True)
        pair = np.arange(len(key))
        two = start[count == 2]
        pair[order[two]] = order[two + 1]
        pair[order[two + 1]] = order[two]
        other = (pair // 3).reshape(-1, 3)
        mine = np.repeat(np.arange(len(f)), 3).reshape(-1, 3)
        self.partner = other  # (F, 3): the face across each side (creases.py's dihedral angles)
        self.edge_normals = _unit(weighted[mine] + weighted[other])
        self.edge_pseudo = self.face_normals[mine] + self.face_normals[other]
        self.tol = MESH_EDGE_TOL * diagonal(v)
        self.vertices = np.ascontiguousarray(v, dtype=float)
        self.faces = np.ascontiguousarray(f, dtype=np.int64)
        self._tree = None
        self.moments = None  # mass_moments's, when first asked
        self.winding = winding_function(*s.source)

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
# libigl's trees freed before the interpreter tears its modules down: a shape still held then (a module's
# object) kept its tree past libigl's own teardown, and nanobind printed a leak report at every such exit
atexit.register(_CACHE.clear)


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
    lam = _barycentric(d, face, c)
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
    vertex = d.faces[face, np.argmax(np.where(near_edge, -np.inf, lam), axis=1)]
    vertex = np.where(count == 3, d.faces[face, np.argmax(lam, axis=1)], vertex)
    normal[corner] = d.vertex_normals[vertex[corner]]
    pseudo[corner] = d.vertex_pseudo[vertex[corner]]
    away = q - c
    distance = np.linalg.norm(away, axis=1)
    inside = np.einsum("ij,ij->i", away, pseudo) < 0
    seam = d.solid.seam[face]
    if seam.any():  # by the outer surface's open edges: the winding number says
        inside[seam] = d.winding(q[seam]) > 0.5
    return c, normal, np.where(inside, -distance, distance), count >= 1


def _barycentric(d, face, c):
    """Barycentric coordinates ``(N, 3)`` of the points ``c`` in the outer surface's triangles ``face``."""
    v, f = d.vertices, d.faces[face]
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
