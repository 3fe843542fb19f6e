"""Validators of an object (its shape, pose, mass and density), done once where it enters.

Each ``check_*`` returns what it checked, arrays as read-only float (faces
int) arrays, and raises :class:`ObjectError` (a ``ValueError``) with one line naming the field
and what is wrong, and the code a grasp file's error gets for it.  :func:`checked` is the one
gate: every geometry function takes its object through it, and so does the grasp-file loader,
which turns the line into a located error.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from ...model import GraspObject, Shape
from .primitives import PRIMITIVES, diagonal

__all__ = [
    "KINDS",
    "NOT_SOLID_HINT",
    "RIGID_TOL",
    "SIZE_RANGE",
    "AREA_TOL",
    "check_shape",
    "check_pose",
    "check_object",
    "checked",
    "accept",
    "ObjectError",
    "check_size",
    "check_extent",
    "degenerate_faces",
    "MeshRepair",
    "merge_vertices",
    "repair_mesh",
]

#: What every ``mesh-not-solid`` error ends with, however the mesh came (a grasp file, a mesh file
#: given to ``synthesize``, Python).
NOT_SOLID_HINT = "repair it (docs/guide/objects.md, Meshes as they come)"

#: The shapes an object may have.
KINDS = (*PRIMITIVES, "mesh")

#: A pose's rotation block must be orthonormal to this (as a path's pose targets).
RIGID_TOL = 1e-9

#: An object's size (the diagonal of its bounding box, after any scale) must lie in this range.
#: The geometry multiplies up to four lengths (a mesh's barycentric coordinates; areas two,
#: volumes three): within 1e-75 to 1e75 every such product stays a normal double (1e-300 to
#: 1e300); beyond it areas overflow or vanish (sampling by area, a contact's distance from a
#: face), as a 1e100 cube's did.
SIZE_RANGE = (1e-75, 1e75)

#: A mesh face whose area is at most ``AREA_TOL`` times the squared size is degenerate (its
#: corners on one line, to round-off: about 1e-16 of the squared size) and has no normal; the
#: thinnest faces trimesh makes (a uv sphere's, a capsule's) are some 2e-5 of it.
AREA_TOL = 1e-12


class ObjectError(ValueError):
    """What is wrong with an object, in one line, with ``code``: the code a grasp file's reader
    gives the same problem (``invalid-size``, ``invalid-mesh``, ``mesh-not-solid``, ...).

    >>> ObjectError("invalid-size", "sphere radius must be a finite number > 0, got 0.0").code
    'invalid-size'
    """

    def __init__(self, code: str, message: str):
        super().__init__(message)
        self.code = code


_SIZE_NAMES = {
    "box": ("a", "b", "c"),
    "sphere": ("radius",),
    "cylinder": ("radius", "height"),
    "capsule": ("radius", "height"),
}


def _real(a, name, dtype=float):
    try:
        a = np.array(a, dtype=dtype)
    except (TypeError, ValueError, OverflowError):
        raise ObjectError("not-a-number", f"{name} must hold real numbers") from None
    return a


def _frozen(a):
    a.setflags(write=False)
    return a


def check_shape(shape: Shape) -> Shape:
    """The shape with its arrays as read-only floats (ints for faces), else ValueError saying what is wrong.

    Every size of a primitive must be finite and > 0 (a capsule of height 0 is
    a sphere: say so).  A mesh needs ``(V, 3)`` finite vertices and ``(F, 3)``
    faces indexing them, closed and consistently oriented (each edge in
    exactly two faces, once in each direction), enclosing a positive volume
    (faces counter-clockwise seen from outside), no face degenerate
    (``degenerate_faces``); every shape's size must be within
    ``SIZE_RANGE`` (``check_extent``, in ``grasptwist.engine.objects.checks``).

    >>> check_shape(Shape("sphere", [0.03])).size.tolist()
    [0.03]
    >>> check_shape(Shape("cylinder", [0.03, -1]))
    Traceback (most recent call last):
    grasptwist.engine.objects.checks.ObjectError: cylinder height must be a finite number > 0, got -1.0
    """
    if not isinstance(shape, Shape):
        raise ObjectError("invalid-object", f"shape must be a Shape, got {type(shape).__name__}")
    if shape.kind not in KINDS:
        raise ObjectError("invalid-object", f"shape kind must be one of {', '.join(KINDS)}, got {shape.kind!r}")
    if shape.kind == "mesh":
        from .mesh import solid_of  # the solid: found once here, kept with the shape (the geometry's cache)

        vertices, faces = _check_mesh(shape.vertices, shape.faces)
        checked = replace(shape, size=_frozen(np.zeros(0)), vertices=vertices, faces=faces)
        try:
            solid_of(checked)
        except ValueError as exc:  # no inside can be told
            raise ObjectError("mesh-not-solid", f"{exc}: {NOT_SOLID_HINT}") from None
        return checked
    return replace(shape, size=check_size(shape.kind, shape.size))


def check_size(kind: str, size) -> np.ndarray:
    """A primitive's sizes as a read-only float ``(n,)`` array, else ValueError naming the field.

    A box has 3 (``a, b, c``), a sphere 1 (``radius``: a number alone will do), a cylinder and a
    capsule 2 (``radius, height``), each finite and > 0.  Cheap (a few microseconds): the
    geometry functions call it where they read a primitive's sizes, so that a ``Shape`` built by
    hand is refused in one line rather than deep inside them.

    >>> check_size("sphere", 0.035).tolist()
    [0.035]
    >>> check_size("box", 0.035)
    Traceback (most recent call last):
    grasptwist.engine.objects.checks.ObjectError: box size must hold 3 number(s) (a, b, c), got 1
    """
    names = _SIZE_NAMES[kind]
    size = _real(size, f"{kind} size").reshape(-1)
    if size.shape != (len(names),):
        raise ObjectError(
            "invalid-size", f"{kind} size must hold {len(names)} number(s) ({', '.join(names)}), got {size.size}"
        )
    for name, value in zip(names, size.tolist()):
        if not (math.isfinite(value) and value > 0):
            raise ObjectError("invalid-size", f"{kind} {name} must be a finite number > 0, got {value!r}")
    check_extent(diagonal(kind, size), kind)
    return _frozen(size)


def check_extent(size: float, what: str = "its") -> float:
    """The object's size (its bounding box's diagonal) when it is within :data:`SIZE_RANGE`, else ValueError
    saying ``what`` size is wrong.

    >>> check_extent(0.1)
    0.1
    >>> check_extent(1e100)
    Traceback (most recent call last):
    grasptwist.engine.objects.checks.ObjectError: its size (the diagonal of its bounding box) is 1e+100, outside 1e-75 to 1e+75 where its areas and volume are double-precision numbers: rescale it
    """
    size = float(size)
    if not math.isfinite(size):
        raise ObjectError("non-finite", f"{what} size overflows double precision: rescale it")
    low, high = SIZE_RANGE
    if not low <= size <= high:
        raise ObjectError(
            "invalid-size",
            f"{what} size (the diagonal of its bounding box) is {size:.3g}, outside {low:.0e} to {high:.0e} "
            "where its areas and volume are double-precision numbers: rescale it",
        )
    return size


def degenerate_faces(vertices, faces) -> np.ndarray:
    r"""The indices of the faces whose area is at most :data:`AREA_TOL` times the squared size ``s``.

    .. math::

        A_f = \tfrac12 |(b - a) \times (c - a)| \le \text{AREA\_TOL}\, s^2

    ``vertices (V, 3)`` float, ``faces (F, 3)`` int; returns ``(k,)`` int, ascending.

    >>> v = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]])
    >>> degenerate_faces(v, np.array([[0, 1, 3], [0, 1, 2]])).tolist()
    [1]
    """
    v = np.asarray(vertices, dtype=float)
    f = np.asarray(faces)
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    size = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    return np.flatnonzero(area <= AREA_TOL * size * size)


class MeshRepair(NamedTuple):
    """A mesh repaired without changing its geometry (:func:`repair_mesh`).

    Attributes
    ----------
    vertices, faces : numpy.ndarray
        ``(V, 3)`` float and ``(F, 3)`` int, read-only: every vertex used, none twice.
    merged : int
        Vertices merged into an equal one.
    dropped : int
        Faces dropped: of zero area (:func:`degenerate_faces`) or with a repeated corner.
    turned : bool
        Every face re-wound outwards (the mesh was wound inwards: a mesh file's reader turns it).
    """

    vertices: np.ndarray
    faces: np.ndarray
    merged: int
    dropped: int
    turned: bool = False

    def warning(self) -> str | None:
        """The ``mesh-repaired`` warning (None when nothing was repaired); it starts with its code.

        >>> MeshRepair(np.zeros((4, 3)), np.zeros((4, 3), int), 2, 1).warning()
        'mesh-repaired: 2 duplicate vertices merged, 1 zero-area face dropped (the geometry is unchanged)'
        >>> MeshRepair(np.zeros((4, 3)), np.zeros((4, 3), int), 0, 0, turned=True).warning()
        'mesh-repaired: faces re-wound outwards (the geometry is unchanged)'
        """
        if not (self.merged or self.dropped or self.turned):
            return None
        said = [f"{self.merged} duplicate vert{'ex' if self.merged == 1 else 'ices'} merged"] if self.merged else []
        said += [f"{self.dropped} zero-area face{'s' * (self.dropped != 1)} dropped"] if self.dropped else []
        said += ["faces re-wound outwards"] if self.turned else []
        return f"mesh-repaired: {', '.join(said)} (the geometry is unchanged)"


def merge_vertices(vertices, faces, decimals=None):
    """Equal vertices merged into the first of them, in the order they come, unused ones left out.

    Vertices are equal when their coordinates are (``decimals`` None), or when they round to the
    same multiples of ``10**-decimals`` (``round(v * 10**decimals)``, as trimesh merges a mesh it
    loads with ``decimals=8``).  ``vertices (V, 3)`` floats, ``faces (F, 3)`` ints indexing them;
    returns ``(vertices (U, 3), faces (F, 3))``, the same triangles.

    >>> v = np.array([[0.0, 0, 0], [5, 5, 5], [1, 0, 0], [0, 1, 0], [1, 1e-9, 0]])
    >>> u, f = merge_vertices(v, [[0, 2, 3], [2, 4, 3]], decimals=8)
    >>> u.tolist(), f.tolist()
    ([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [[0, 1, 2], [1, 1, 2]])
    """
    v = np.asarray(vertices, dtype=float)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    used = np.unique(f)
    key = v[used] if decimals is None else np.round(v[used] * 10**decimals).astype(np.int64)
    _, first, merged = np.unique(key, axis=0, return_index=True, return_inverse=True)
    rank = np.empty(len(first), dtype=np.int64)
    rank[np.argsort(first)] = np.arange(len(first))  # in the order the vertices come
    index = np.zeros(len(v), dtype=np.int64)
    index[used] = rank[merged.reshape(-1)]
    return v[used[np.sort(first)]], index[f]


def repair_mesh(vertices, faces) -> MeshRepair:
    """Equal vertices merged, faces of zero area or with a repeated corner dropped, unused vertices left out.

    Neither changes the solid: a zero-area face subtends no solid angle, and merging equal
    vertices only joins faces that meet there (an STL repeats each vertex in every face).
    ``vertices (V, 3)`` finite floats, ``faces (F, 3)`` ints indexing them.

    >>> v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 0, 0]])
    >>> r = repair_mesh(v, np.array([[0, 2, 1], [0, 4, 3], [0, 3, 2], [1, 2, 3], [0, 1, 4]]))
    >>> len(r.vertices), r.faces.tolist(), r.merged, r.dropped
    (4, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], 1, 1)
    """
    unique, f = merge_vertices(vertices, faces)
    used = np.unique(np.asarray(faces, dtype=np.int64))
    repeated = (f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 2] == f[:, 0])
    keep = ~repeated
    keep[np.flatnonzero(keep)[degenerate_faces(unique, f[keep])]] = False
    kept, f = np.unique(f[keep], return_inverse=True)
    return MeshRepair(
        _frozen(np.ascontiguousarray(unique[kept])),
        _frozen(np.ascontiguousarray(f.reshape(-1, 3))),
        len(used) - len(unique),
        int((~keep).sum()),
    )


def _check_mesh(vertices, faces):
    if vertices is None or faces is None:
        raise ObjectError("invalid-mesh", "mesh needs vertices and faces")
    v = _real(vertices, "mesh vertices")
    if v.ndim != 2 or v.shape[1] != 3 or len(v) < 4:
        raise ObjectError("invalid-mesh", f"mesh vertices must have shape (V, 3) with V >= 4, got {v.shape}")
    if not np.isfinite(v).all():
        row = int(np.flatnonzero(~np.isfinite(v).all(axis=1))[0])
        raise ObjectError("non-finite", f"mesh vertex {row} is not finite: {v[row].tolist()}")
    f = _real(faces, "mesh faces", dtype=np.float64)
    if f.ndim != 2 or f.shape[1] != 3 or len(f) < 1:
        raise ObjectError("invalid-mesh", f"mesh faces must have shape (F, 3) with F >= 1, got {f.shape}")
    if not (np.isfinite(f).all() and (f == np.round(f)).all() and f.min() >= 0 and f.max() < len(v)):
        raise ObjectError("invalid-mesh", f"mesh faces must be whole vertex indices from 0 to {len(v) - 1}")
    check_extent(np.linalg.norm(v.max(axis=0) - v.min(axis=0)), "mesh")
    repaired = repair_mesh(v, f.astype(np.int64))
    if len(repaired.faces) == 0:
        raise ObjectError("mesh-not-solid", f"mesh bounds no solid: every face has zero area: {NOT_SOLID_HINT}")
    return repaired.vertices, repaired.faces


def check_pose(pose) -> np.ndarray:
    """The ``(4, 4)`` rigid pose as a read-only float array, else ValueError saying what is wrong.

    Its rotation block must be orthonormal to ``RIGID_TOL`` (1e-9) with
    determinant +1, its last row ``(0, 0, 0, 1)``.

    >>> check_pose(np.diag([1.0, 1, -1, 1]))
    Traceback (most recent call last):
    grasptwist.engine.objects.checks.ObjectError: pose must be rigid: its rotation block is not a rotation (orthonormal, determinant +1)
    """
    p = _real(pose, "pose")
    if p.shape != (4, 4):
        raise ObjectError("invalid-pose", f"pose must have shape (4, 4), got {p.shape}")
    if not np.isfinite(p).all():
        raise ObjectError("non-finite", "pose must be finite")
    if not (p[3] == (0.0, 0.0, 0.0, 1.0)).all():
        raise ObjectError(
            "invalid-pose", f"pose must be rigid: its last row must be (0, 0, 0, 1), got {tuple(p[3].tolist())}"
        )
    r = p[:3, :3]
    if not (np.abs(r.T @ r - np.eye(3)).max() <= RIGID_TOL and np.linalg.det(r) > 0):
        raise ObjectError(
            "invalid-pose", "pose must be rigid: its rotation block is not a rotation (orthonormal, determinant +1)"
        )
    return _frozen(p)


def check_object(obj: GraspObject) -> GraspObject:
    """The object with its shape and pose checked, else ValueError saying what is wrong.

    ``mass`` and ``density``, when given, must be finite and > 0.

    >>> check_object(GraspObject(Shape("box", [1, 1, 1]), np.eye(4), mass=0.0))
    Traceback (most recent call last):
    grasptwist.engine.objects.checks.ObjectError: object mass must be a finite number > 0, got 0.0
    """
    if not isinstance(obj, GraspObject):
        raise ObjectError("invalid-object", f"object must be a GraspObject, got {type(obj).__name__}")
    for name in ("mass", "density"):
        value = getattr(obj, name)
        if value is not None:
            try:
                good = math.isfinite(value) and value > 0
            except TypeError:
                good = False
            if not good:
                raise ObjectError(f"invalid-{name}", f"object {name} must be a finite number > 0, got {value!r}")
    return replace(obj, shape=check_shape(obj.shape), pose=check_pose(obj.pose))


#: Objects :func:`checked` gave back (accepted, or made by it), and its answer for the others.
_ACCEPTED: weakref.WeakSet = weakref.WeakSet()
_CHECKED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def checked(obj: GraspObject) -> GraspObject:
    """``obj`` checked by :func:`check_object` once: the one gate every geometry function (and so
    the search, the weight, a hand's reach) takes an object through, however it was built.

    The answer is kept while ``obj`` lives, so a search asking thousands of times checks a mesh
    once; an object it gave back passes straight through.  Raises :class:`ObjectError`.

    >>> cube = GraspObject(Shape("box", [0.065, 0.065, 0.065]), np.eye(4))
    >>> checked(cube) is checked(checked(cube))
    True
    >>> checked(GraspObject(Shape("box", [0.065, 0.065, 0.065]), np.eye(4), density=-1.0))
    Traceback (most recent call last):
    grasptwist.engine.objects.checks.ObjectError: object density must be a finite number > 0, got -1.0
    """
    if not isinstance(obj, GraspObject):
        return check_object(obj)  # which says what it is instead
    if obj in _ACCEPTED:
        return obj
    twin = _CHECKED.get(obj)
    if twin is None:
        twin = check_object(obj)
        _ACCEPTED.add(twin)
        _CHECKED[obj] = twin
    return twin


def accept(obj: GraspObject) -> GraspObject:
    """Mark ``obj``, made from an object :func:`checked` accepted by a change that keeps it valid
    (a pose checked by :func:`check_pose`), as accepted; return it."""
    _ACCEPTED.add(obj)
    return obj
