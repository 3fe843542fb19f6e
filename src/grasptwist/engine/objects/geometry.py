r"""An object's geometry in the grasp frame: nearest surface points, mass properties, samples, triangles.

Each function takes a :class:`~grasptwist.model.GraspObject` through the one gate,
:func:`~.checks.checked` (:func:`~grasptwist.objects.check_object` once per object, however it
was built: an object that is not one raises :class:`~.checks.ObjectError` with the code a grasp
file's reader gives it) and works in the grasp frame: points go into
the object's frame through its pose :math:`T = (R, t)`, :math:`q = R^T (p - t)`,
are answered there by ``primitives`` (exact) or ``mesh``, and come
back as :math:`R c + t` (points) and :math:`R n` (normals).  Normals point
into the object, as a grasp's do; distances are signed, > 0 outside, so that
a point ``p`` satisfies

.. math::

    c = p + d\, n

with ``c`` its nearest surface point, ``d`` its signed distance and ``n``
the unit inward normal there: every point for a primitive; for a mesh,
those whose nearest point is inside a face (at an edge or vertex ``n`` is
the normal of the faces there, not the direction from ``p``, and only
:math:`|c - p| = |d|` holds).
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np

from ...model import GraspObject
from ..se3 import rotate
from . import primitives
from .checks import accept, check_pose, check_size, checked
from .tolerances import EDGE_TOL


def _mesh():
    """:mod:`.mesh` (and the winding-number solid it brings, :mod:`.solid`), imported at first use:
    a run whose objects are all primitives never needs them (start-up, ``bench/startup.py``)."""
    from . import mesh

    return mesh


__all__ = [
    "SurfacePoints",
    "MassProperties",
    "project_to_surface",
    "signed_distance",
    "mass_properties",
    "sample_surface",
    "tessellate",
    "object_size",
    "moved",
    "body_areas",
    "body_of",
    "on_hidden_face",
]


class SurfacePoints(NamedTuple):
    """Points put on an object's surface (:func:`project_to_surface`).

    Attributes
    ----------
    points : numpy.ndarray
        ``(..., 3)`` the nearest surface point of each given point.
    normals : numpy.ndarray
        ``(..., 3)`` the unit inward normal there.
    distance : numpy.ndarray
        ``(...)`` each given point's signed distance from the surface: > 0
        outside, < 0 inside.
    on_edge : numpy.ndarray
        ``(...)`` bool: the nearest point is on an edge or corner, where the surface has no one
        normal and ``normals`` holds the faces' average: within ``EDGE_TOL`` of the size of a
        box's edge or corner or a cylinder's rim, within ``MESH_EDGE_TOL`` of a mesh's edge or
        vertex (one between coplanar faces too); never on a sphere or capsule.
    """

    points: np.ndarray
    normals: np.ndarray
    distance: np.ndarray
    on_edge: np.ndarray


class MassProperties(NamedTuple):
    """An object's volume, mass, centre of mass and inertia tensor (:func:`mass_properties`).

    Attributes
    ----------
    volume : float
        In cubed length units.
    mass : float or None
        The given mass, else ``density * volume``; None when neither is given.
    center_of_mass : numpy.ndarray
        ``(3,)`` in the grasp frame (the centroid of the solid: uniform density).
    inertia : numpy.ndarray or None
        ``(3, 3)`` the inertia tensor about the centre of mass, in the grasp frame's axes (mass
        times squared length units), of the mass spread uniformly over the solid; None without a mass.
    """

    volume: float
    mass: float | None
    center_of_mass: np.ndarray
    inertia: np.ndarray | None = None


def object_size(obj: GraspObject) -> float:
    """The diagonal of the object's bounding box in its own frame: the scale of every tolerance.

    In its own frame so that it does not change as the object moves.

    >>> from grasptwist.objects import Shape
    >>> object_size(GraspObject(Shape("box", np.array([0.03, 0.04, 0.12])), np.eye(4)))
    0.13
    """
    shape = checked(obj).shape
    if shape.kind == "mesh":
        return _mesh().diagonal(shape.vertices)
    return primitives.diagonal(shape.kind, check_size(shape.kind, shape.size))


def project_to_surface(obj: GraspObject, points) -> SurfacePoints:
    r"""Each point's nearest point on the object's surface, the inward normal there and its signed distance.

    Exact for the primitives (``grasptwist.engine.objects.primitives`` says which answer a point
    without a unique nearest point gets); for a mesh, the nearest point of its
    triangles with that face's normal, or within
    :data:`~grasptwist.objects.MESH_EDGE_TOL` of an edge or vertex the area-weighted
    normal of the faces there (``grasptwist.engine.objects.mesh``).

    .. math::

        |d| = \min_{s \in \partial O} |p - s| = |c - p|, \qquad c = p + d\, n

    (the second for a mesh only inside a face).

    Parameters
    ----------
    obj : GraspObject
        Checked by :func:`~grasptwist.objects.check_object`.
    points : array-like, shape (..., 3)
        Points in the grasp frame.

    Returns
    -------
    SurfacePoints
        ``points (..., 3)``, ``normals (..., 3)`` (unit, inward),
        ``distance (...)`` (> 0 outside), ``on_edge (...)`` (the nearest point is on an
        edge, corner, rim or mesh vertex: its normal is an average); NaN (``on_edge``
        False) for a point that is not finite (never an exception, as everywhere in the engine).

    Examples
    --------
    A 2 x 2 x 2 box moved 1 along x; a point 0.5 beyond its +y face:

    >>> from grasptwist.objects import Shape
    >>> pose = np.eye(4)
    >>> pose[0, 3] = 1.0
    >>> box = GraspObject(Shape("box", np.array([2.0, 2.0, 2.0])), pose)
    >>> s = project_to_surface(box, [1.0, 1.5, 0.0])
    >>> s.points.tolist(), s.normals.tolist(), float(s.distance), bool(s.on_edge)
    ([1.0, 1.0, 0.0], [0.0, -1.0, 0.0], 0.5, False)
    """
    p, obj = _points(points), checked(obj)
    rotation, translation = obj.pose[:3, :3], obj.pose[:3, 3]
    # written out component by component (se3.rotate): a BLAS product of (N, 3) by (3, 3) is
    # several times slower, and its threads fight over a busy machine
    with np.errstate(invalid="ignore", over="ignore"):  # inf * 0 in a point that is not finite
        local = rotate(rotation.T, p - translation).reshape(-1, 3)
    finite = np.isfinite(local).all(axis=1)
    if finite.all():  # the common case, without the copies
        c, outward, d, edge = _nearest(obj, local)
    else:
        c, outward, d = np.full_like(local, np.nan), np.full_like(local, np.nan), np.full(len(local), np.nan)
        edge = np.zeros(len(local), dtype=bool)
        c[finite], outward[finite], d[finite], edge[finite] = _nearest(obj, local[finite])
    return SurfacePoints(
        (rotate(rotation, c) + translation).reshape(p.shape),
        (rotate(-rotation, outward) + 0.0).reshape(p.shape),  # + 0.0: zeros without a sign, for records
        d.reshape(p.shape[:-1]),
        edge.reshape(p.shape[:-1]),
    )


def signed_distance(obj: GraspObject, points) -> np.ndarray:
    """``project_to_surface(obj, points).distance``, the same numbers, without the nearest points and
    normals: ``(..., 3) -> (...)`` (a primitive's alone is cheaper; a mesh's is the projection's).

    >>> from grasptwist.objects import Shape
    >>> box = GraspObject(Shape("box", np.array([2.0, 2.0, 2.0])), np.eye(4))
    >>> signed_distance(box, [[1.0, 1.5, 0.0], [0.0, 0.0, 0.5]]).tolist()
    [0.5, -0.5]
    """
    p = _points(points)
    shape = obj.shape
    if shape.kind == "mesh":
        return project_to_surface(obj, p).distance
    rotation, translation = obj.pose[:3, :3], obj.pose[:3, 3]
    with np.errstate(invalid="ignore", over="ignore"):  # inf * 0 in a point that is not finite
        local = rotate(rotation.T, p - translation).reshape(-1, 3)
        d = primitives.signed_distance(shape.kind, check_size(shape.kind, shape.size), local)
    return np.where(np.isfinite(local).all(axis=1), d, np.nan).reshape(p.shape[:-1])


def _nearest(obj, local):
    shape = obj.shape
    if shape.kind == "mesh":
        return _mesh().nearest(shape, local)
    return primitives.nearest(shape.kind, check_size(shape.kind, shape.size), local, EDGE_TOL * object_size(obj))


def _points(points):
    try:
        p = np.asarray(points, dtype=float)
    except (TypeError, ValueError):
        raise ValueError("points must be real numbers of shape (..., 3)") from None
    if p.shape[-1:] != (3,):
        raise ValueError(f"points must have shape (..., 3), got {p.shape}")
    return p


def mass_properties(obj: GraspObject) -> MassProperties:
    r"""The object's volume, its mass (given, or from its density), its centre of mass and inertia tensor in the grasp frame.

    .. math::

        m = \rho V, \qquad c = R\, c_O + t, \qquad
        I = \frac{m}{V} R \left(\operatorname{tr}(J) I_3 - J\right) R^T

    with :math:`c_O` the centroid in the object's frame and :math:`J = \int (x - c_O)(x - c_O)^T dV`
    its second moment of volume: closed forms for a primitive (``primitives.second_moment``,
    centred on its origin); for a mesh, those of the solid it bounds (``mesh.mass_moments``: by
    the divergence theorem on a closed surface, along rays through its winding number else).

    >>> from grasptwist.objects import Shape
    >>> pose = np.eye(4)
    >>> pose[:3, 3] = [0, 0, 0.05]
    >>> m = mass_properties(GraspObject(Shape("box", np.array([0.1, 0.1, 0.1])), pose, density=1000.0))
    >>> round(m.volume, 6), round(m.mass, 6), m.center_of_mass.tolist(), np.diag(m.inertia).round(8).tolist()
    (0.001, 1.0, [0.0, 0.0, 0.05], [0.00166667, 0.00166667, 0.00166667])
    """
    obj = checked(obj)
    shape = obj.shape
    if shape.kind == "mesh":
        volume, centroid, second = _mesh().mass_moments(shape)
    else:
        size = check_size(shape.kind, shape.size)
        volume, centroid, second = (
            primitives.volume(shape.kind, size),
            np.zeros(3),
            primitives.second_moment(shape.kind, size),
        )
    mass = obj.mass if obj.mass is not None else (None if obj.density is None else obj.density * volume)
    rotation = obj.pose[:3, :3]
    inertia = None
    if mass is not None:
        inertia = rotation @ ((np.trace(second) * np.eye(3) - second) * (mass / volume)) @ rotation.T
    return MassProperties(volume, mass, rotation @ centroid + obj.pose[:3, 3], inertia)


def sample_surface(obj: GraspObject, n: int, rng: np.random.Generator, *, body=None) -> tuple[np.ndarray, np.ndarray]:
    """``n`` points uniformly distributed over the object's surface (by area), with the inward normals there.

    The same generator state gives the same points (``primitives.sample`` and
    ``mesh.sample`` in ``grasptwist.engine.objects`` say how they are drawn).  A mesh's points
    are on its solid's outer surface (never on a face inside it, nor round a cavity); ``body``
    (an int, a mesh's only) draws them from that body alone (``geometry.body_areas`` lists them).

    Returns
    -------
    points, normals : numpy.ndarray
        Shape ``(n, 3)`` each, in the grasp frame; the normals unit and inward.

    Examples
    --------
    >>> from grasptwist.objects import Shape
    >>> ball = GraspObject(Shape("sphere", np.array([1.0])), np.eye(4))
    >>> p, n = sample_surface(ball, 3, np.random.default_rng(1))
    >>> np.allclose(p, -n)
    True
    """
    obj = checked(obj)
    shape = obj.shape
    if shape.kind == "mesh":
        points, outward = _mesh().sample(shape, n, rng, body=body)
    else:
        points, outward = primitives.sample(shape.kind, check_size(shape.kind, shape.size), n, rng)
    rotation, translation = obj.pose[:3, :3], obj.pose[:3, 3]
    return rotate(rotation, points) + translation, rotate(-rotation, outward)


def body_areas(obj: GraspObject) -> np.ndarray:
    """The area of each body's outer surface (pieces of a mesh that neither overlap nor touch): ``(bodies,)``;
    a primitive is one body (its area unused: ``[1.0]``).

    >>> from grasptwist.objects import Shape
    >>> body_areas(GraspObject(Shape("sphere", np.ones(1)), np.eye(4))).tolist()
    [1.0]
    """
    return _mesh().body_areas(obj.shape) if obj.shape.kind == "mesh" else np.ones(1)


def body_of(obj: GraspObject, points) -> np.ndarray:
    """The body nearest each point ``(..., 3)`` in the grasp frame: ``(...)`` int (0 for a primitive).

    >>> from grasptwist.objects import Shape
    >>> body_of(GraspObject(Shape("sphere", np.ones(1)), np.eye(4)), np.zeros((2, 3))).tolist()
    [0, 0]
    """
    p = _points(points)
    if obj.shape.kind != "mesh":
        return np.zeros(p.shape[:-1], dtype=np.int64)
    local = rotate(obj.pose[:3, :3].T, p - obj.pose[:3, 3]).reshape(-1, 3)
    return _mesh().body_of(obj.shape, local).reshape(p.shape[:-1])


def on_hidden_face(obj: GraspObject, points, distance, tolerance: float) -> np.ndarray:
    """Whether each point ``(..., 3)`` lies on a face of the mesh that no finger can reach: within
    ``tolerance`` (a length) of one of its faces, but deeper than ``tolerance`` inside the solid (its signed
    ``distance (...)`` from the outer surface, :func:`project_to_surface`'s): a face inside another
    piece, or round a cavity.  Never for a primitive.

    >>> from grasptwist.objects import Shape
    >>> on_hidden_face(GraspObject(Shape("sphere", np.ones(1)), np.eye(4)), np.zeros((1, 3)), [-1.0], 0.01).tolist()
    [False]
    """
    p = _points(points)
    deep = np.asarray(distance, dtype=float) < -tolerance
    if obj.shape.kind != "mesh" or not deep.any():
        return np.zeros(p.shape[:-1], dtype=bool)
    local = rotate(obj.pose[:3, :3].T, p - obj.pose[:3, 3]).reshape(-1, 3)
    near = _mesh().face_distance(obj.shape, local).reshape(p.shape[:-1]) <= tolerance
    return deep & near


def tessellate(obj: GraspObject, *, segments: int = 32) -> tuple[np.ndarray, np.ndarray]:
    """A closed triangle mesh of the object in the grasp frame, for pictures and collisions.

    A mesh is itself; a primitive's round parts get ``segments`` vertices per
    ring (``grasptwist.engine.objects.primitives.triangles``), on its exact surface.

    Returns
    -------
    vertices : numpy.ndarray
        ``(V, 3)`` in the grasp frame.
    faces : numpy.ndarray
        ``(F, 3)`` int, counter-clockwise seen from outside.

    Examples
    --------
    >>> from grasptwist.objects import Shape
    >>> v, f = tessellate(GraspObject(Shape("box", np.ones(3)), np.eye(4)))
    >>> v.shape, f.shape
    ((8, 3), (12, 3))
    """
    obj = checked(obj)
    shape = obj.shape
    if shape.kind == "mesh":
        vertices, faces = shape.vertices, shape.faces.copy()
    else:
        vertices, faces = primitives.triangles(shape.kind, check_size(shape.kind, shape.size), segments)
    return rotate(obj.pose[:3, :3], vertices) + obj.pose[:3, 3], faces


def moved(obj: GraspObject, pose) -> GraspObject:
    """The object carried by the rigid motion ``pose`` (``(4, 4)``, in the grasp frame): its pose becomes ``pose @ obj.pose``.

    >>> from grasptwist.objects import Shape
    >>> step = np.eye(4); step[2, 3] = 1.0
    >>> moved(GraspObject(Shape("sphere", np.ones(1)), np.eye(4)), step).pose[:3, 3].tolist()
    [0.0, 0.0, 1.0]
    """
    obj = checked(obj)
    new = check_pose(pose) @ obj.pose
    new.setflags(write=False)
    return accept(replace(obj, pose=new))
