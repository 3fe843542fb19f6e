"""A URDF's joints and links, read from its XML tree with yourdfpy's conventions, without yourdfpy.

:mod:`grasptwist.io.urdf` parses a URDF with lxml (no DTD, no entities, size limits on) and
builds its hand from this model; :func:`~grasptwist.io.urdf_meshes.link_geometry` poses the
finger links' collision geometry from it.  yourdfpy imports trimesh (and with it scipy.optimize,
networkx, ...) when it is imported: 0.43 s of every command that reads a hand, a tenth of a
synthesis's budget (issue 37).  What is read, as yourdfpy reads it:

* ``<joint>``: ``name``, ``type``, ``<parent link>``, ``<child link>``; ``<origin xyz rpy>``
  (each ``0 0 0`` when missing, the whole origin the identity when there is none) as the pose
  ``T(xyz) Rz(y) Ry(p) Rx(r)`` (:func:`~grasptwist.engine.se3.rpy_to_matrix`); ``<axis xyz>``
  (``1 0 0`` when missing); ``<limit effort velocity lower upper>`` (each None when missing);
  whether it has a ``<mimic>``;
* ``<link>``: ``name``, and each ``<collision>`` and ``<visual>``: its ``<origin>`` and the first
  element of its ``<geometry>``: ``<box size>``, ``<sphere radius>``, ``<cylinder radius length>``
  or ``<mesh filename scale>`` (``scale`` one number for all three axes or three, commas allowed
  between them as yourdfpy allows; none: 1).

Everything else (inertials, materials, transmissions, ``<gazebo>``) is passed over unread.  What
is read is checked where it stands: a bad number or a missing element is ``invalid-urdf`` at its
line, rather than whatever yourdfpy raised without one.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from ..engine.objects.checks import merge_vertices
from ..engine.se3 import rpy_to_matrix
from ..model import InputError

__all__ = ["MERGE_DECIMALS", "UrdfJoint", "UrdfLimit", "UrdfLink", "UrdfModel", "UrdfShape", "merged", "read_model"]

#: A link mesh's vertices that round to the same multiples of ``10**-MERGE_DECIMALS`` are one, as
#: trimesh merges a mesh it loads (``trimesh.tol.merge``, 1e-8).
MERGE_DECIMALS = 8


class UrdfLimit(NamedTuple):
    """A joint's ``<limit>``: each attribute a float, None when the element leaves it out."""

    effort: float | None
    velocity: float | None
    lower: float | None
    upper: float | None


class UrdfJoint(NamedTuple):
    """A ``<joint>``: its ``origin`` ``(4, 4)`` in the parent link, ``axis`` ``(3,)`` in its own frame."""

    name: str
    type: str
    parent: str
    child: str
    origin: np.ndarray
    axis: np.ndarray
    limit: UrdfLimit | None
    mimic: bool
    line: int


class UrdfShape(NamedTuple):
    """A ``<collision>`` or ``<visual>``: its ``origin`` ``(4, 4)`` in the link and its geometry.

    ``kind`` is ``"box"`` (``size`` its three edges), ``"sphere"`` (``size`` its radius),
    ``"cylinder"`` (``size`` its radius and length, along z) or ``"mesh"`` (``filename`` as
    written, ``scale`` ``(3,)``); ``line`` the geometry element's (where a mesh's problems are
    reported).
    """

    kind: str
    origin: np.ndarray
    size: tuple = ()
    filename: str | None = None
    scale: np.ndarray | None = None
    line: int | None = None


class UrdfLink(NamedTuple):
    """A ``<link>``: its collision and visual shapes, in the file's order."""

    name: str
    collisions: tuple
    visuals: tuple


class UrdfModel(NamedTuple):
    """A URDF's links by name (in the file's order) and its joints (in the file's order)."""

    links: dict
    joints: tuple


#: Attributes read as numbers: how many numbers each holds.
_NUMBERS = {("origin", "xyz"): 3, ("origin", "rpy"): 3, ("axis", "xyz"): 3}
_LIMITS = ("effort", "velocity", "lower", "upper")
#: Each primitive's attributes and the numbers each holds (a mesh: a filename and a scale).
_SHAPES = {"box": (("size", 3),), "sphere": (("radius", 1),), "cylinder": (("radius", 1), ("length", 1)), "mesh": ()}


def read_model(root, file) -> UrdfModel:
    """The joints and links of a URDF's XML tree ``root`` (``<robot>``), checked where they stand.

    Raises
    ------
    InputError
        ``invalid-urdf`` at the element's line: a joint or link without a name, two joints or
        two links of one name, a joint without a type, parent or child, a number that is none
        (or not finite), a box's, sphere's or cylinder's size not above 0, a ``<collision>`` or
        ``<visual>`` without a geometry.

    >>> from lxml import etree
    >>> root = etree.fromstring(b'<robot name="r"><link name="a"/><link name="b"><collision>'
    ...     b'<geometry><mesh filename="b.stl" scale="0.001"/></geometry></collision></link>'
    ...     b'<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
    ...     b'<origin xyz="0 0 1" rpy="0 0 1.5707963267948966"/></joint></robot>')
    >>> model = read_model(root, "r.urdf")
    >>> (j,) = model.joints
    >>> j.axis.tolist(), (j.origin.round(12)[:3] + 0.0).tolist(), j.limit
    ([1.0, 0.0, 0.0], [[0.0, -1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 1.0]], None)
    >>> model.links["b"].collisions[0].scale.tolist()
    [0.001, 0.001, 0.001]
    """
    joints = tuple(_joint(element, file) for element in root.iterfind("joint"))
    _unique("joint", [(j.name, j.line) for j in joints], file)
    elements = list(root.iterfind("link"))
    for element in elements:
        if not element.get("name"):
            raise InputError("invalid-urdf", "a <link> without a name", file, element.sourceline)
    _unique("link", [(e.get("name"), e.sourceline) for e in elements], file)
    links = {}
    for element in elements:
        name = element.get("name")
        shapes = [
            tuple(_shape(child, f"link {name!r}: <{tag}>", file) for child in element.iterfind(tag))
            for tag in ("collision", "visual")
        ]
        links[name] = UrdfLink(name, *shapes)
    return UrdfModel(links, joints)


def _unique(tag, named, file):
    """Refuse a name given twice among ``named``'s ``(name, line)``: ``invalid-urdf`` at the second's
    line, naming the first's (pinocchio refuses such a URDF; yourdfpy keeps the last of them)."""
    first = {}
    for name, line in named:
        if name in first:
            raise InputError(
                "invalid-urdf", f"a second <{tag}> named {name!r} (the first at line {first[name]})", file, line
            )
        first[name] = line


def _joint(element, file):
    line = element.sourceline
    name = element.get("name")
    if not name:
        raise InputError("invalid-urdf", "a <joint> without a name", file, line)
    kind = element.get("type")
    if kind is None:
        raise InputError("invalid-urdf", f"joint {name!r}: no type", file, line)
    ends = []
    for tag in ("parent", "child"):
        child = element.find(tag)
        if child is None or not child.get("link"):
            raise InputError("invalid-urdf", f"joint {name!r}: no <{tag} link=...>", file, line)
        ends.append(child.get("link"))
    what = f"joint {name!r}"
    origin = _origin(element.find("origin"), what, file)
    axis = element.find("axis")
    axis = np.array([1.0, 0.0, 0.0]) if axis is None else _vector(axis, "xyz", "1 0 0", what, file)
    limit = element.find("limit")
    if limit is not None:
        limit = UrdfLimit(*(_number(limit, attribute, what, file) for attribute in _LIMITS))
    return UrdfJoint(name, kind, *ends, origin, axis, limit, element.find("mimic") is not None, line)


def _origin(element, what, file):
    """An ``<origin>``'s pose ``(4, 4)``: the identity when there is none."""
    pose = np.eye(4)
    if element is not None:
        pose[:3, 3] = _vector(element, "xyz", "0 0 0", what, file)
        pose[:3, :3] = rpy_to_matrix(_vector(element, "rpy", "0 0 0", what, file))
    return pose


def _number(element, attribute, what, file):
    """An attribute's one number, None when the element leaves it out."""
    text = element.get(attribute)
    return (
        None if text is None else _numbers(text, 1, f"{what}: <{element.tag} {attribute}>", file, element.sourceline)[0]
    )


def _vector(element, attribute, default, what, file):
    text = element.get(attribute, default)
    return np.array(_numbers(text, 3, f"{what}: <{element.tag} {attribute}>", file, element.sourceline))


def _shape(element, what, file):
    """A ``<collision>`` or ``<visual>``: the first element of its ``<geometry>``, as yourdfpy takes it."""
    geometry = element.find("geometry")
    first = None if geometry is None else next((c for c in geometry if isinstance(c.tag, str)), None)
    if first is None:
        raise InputError("invalid-urdf", f"{what} without a <geometry> element", file, element.sourceline)
    kind, line = first.tag, first.sourceline
    if kind not in _SHAPES:
        raise InputError("invalid-urdf", f"{what}: unknown geometry <{kind}>", file, line)
    origin = _origin(element.find("origin"), what, file)
    if kind == "mesh":
        filename = first.get("filename")
        if not filename:
            raise InputError("invalid-urdf", f"{what}: <mesh> without a filename", file, line)
        text = first.get("scale", "").replace(",", " ")
        count = 1 if len(text.split()) == 1 else 3
        scale = np.broadcast_to(_numbers(text, count, f"{what}: <mesh scale>", file, line), 3) if text.strip() else None
        return UrdfShape(kind, origin, filename=filename, scale=None if scale is None else scale.copy(), line=line)
    size = []
    for attribute, count in _SHAPES[kind]:
        text = first.get(attribute)
        if text is None:
            raise InputError("invalid-urdf", f"{what}: <{kind}> without {attribute}", file, line)
        numbers = _numbers(text.replace(",", " "), count, f"{what}: <{kind} {attribute}>", file, line)
        if min(numbers) <= 0:  # no solid: trimesh makes NaN or a flat mesh of it
            raise InputError(
                "invalid-urdf", f"{what}: <{kind} {attribute}> must be above 0, got {text[:40]!r}", file, line
            )
        size += numbers
    return UrdfShape(kind, origin, tuple(size), line=line)


def _numbers(text, count, what, file, line):
    """The ``count`` finite numbers of an attribute's ``text``, else ``invalid-urdf`` at ``line``."""
    try:
        values = [float(word) for word in text.split()]
    except ValueError:
        values = None
    if values is None or len(values) != count or not all(map(math.isfinite, values)):
        raise InputError("invalid-urdf", f"{what}: expected {count} finite number(s), got {text[:40]!r}", file, line)
    return values


def merged(vertices, faces):
    """A link mesh's ``(vertices, faces)`` as trimesh loads it: faces with a corner that is not
    finite dropped, vertices equal to :data:`MERGE_DECIMALS` decimals merged into the first of them
    (:func:`~grasptwist.engine.objects.checks.merge_vertices`), unused ones left out.

    >>> v, f = merged([[0, 0, 0], [1, 0, 0], [0, 1, 0], [np.nan, 0, 0], [0, 0, 1e-9]], [[0, 1, 2], [1, 3, 2], [4, 1, 2]])
    >>> v.tolist(), f.tolist()
    ([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [[0, 1, 2], [0, 1, 2]])
    """
    v = np.asarray(vertices, dtype=float)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    return merge_vertices(v, f[np.isfinite(v).all(axis=1)[f].all(axis=1)], decimals=MERGE_DECIMALS)
