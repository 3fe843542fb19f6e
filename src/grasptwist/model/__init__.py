"""The data types every layer shares: grasps, twists, objects and input errors.

No parsing and no math here: the loaders in :mod:`grasptwist.io` build these,
the runner in :mod:`grasptwist.run` feeds them to the engine, and the
writers in :mod:`grasptwist.output` report them.  A hand's types (:mod:`.hands`) and the
environment's (:mod:`.environment`) are named here too, their modules imported on first use:
Python compiles a dataclass's methods as its module loads, and a grasp without a hand or an
environment needs none of theirs (bench/startup.py).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .environment import Environment
    from .hands import Hand, HandPlacement

__all__ = [
    "Twist",
    "Wrench",
    "Grasp",
    "Shape",
    "GraspObject",
    "Obstacle",
    "Environment",
    "Segment",
    "ObjectPath",
    "InputError",
    "CONTACT_NAMES",
    "Joint",
    "Finger",
    "Hand",
    "HandPlacement",
]

#: Contact names of a grasp that does not name its contacts.
CONTACT_NAMES = ("1", "2", "3")


@dataclass(frozen=True, eq=False)
class Twist:
    """A desired object twist from a grasp file.

    Attributes
    ----------
    name : str
        Its ``name``, or ``"1"``, ``"2"``, ... by position in ``twists``.
    screw : numpy.ndarray
        ``(6,)`` read-only ``(omega; v)``, ``v`` the velocity of the frame
        origin (``at`` already applied).
    line : int or None
        1-based line of the twist's entry in the file.
    """

    name: str
    screw: np.ndarray
    line: int | None


@dataclass(frozen=True, eq=False)
class Wrench:
    """A wrench the fingers must exert on the object, from a grasp file.

    Attributes
    ----------
    name : str
        Its ``name``, or ``"1"``, ``"2"``, ... by position in ``wrenches``;
        ``"hold"`` for the one that ``mass`` adds.
    wrench : numpy.ndarray
        ``(6,)`` read-only ``(force; moment about the origin)``.
    line : int or None
        1-based line of its entry in the file (of ``mass`` for ``hold``).
    """

    name: str
    wrench: np.ndarray
    line: int | None


@dataclass(frozen=True, eq=False)
class Grasp:
    """One grasp (one YAML document) of a grasp file.

    Arrays are read-only.  ``eq=False``: dataclass equality would compare
    arrays with ``==`` and fail; compare fields explicitly instead.

    Attributes
    ----------
    name : str
        Its ``name``; by default the file's stem, or ``stem#k`` (``k``
        counting documents from 1) when the file yields several entries.
    units : str or None
        The ``units`` label, echoed in outputs.
    file : str
        The file as named by the caller (``"<stdin>"``, ``"<string>"``).
    document : int
        0-based index of the document in the stream.
    contact_names : tuple of str
        Names of contacts 1, 2, 3 (default ``"1"``, ``"2"``, ``"3"``).
    points : numpy.ndarray
        ``(3, 3)``, row ``i`` the contact point ``p_i``.
    normals : numpy.ndarray
        ``(3, 3)``, row ``i`` the unit normal ``n_i`` pointing into the object.
    wrist : numpy.ndarray or None
        ``(3,)`` wrist point ``c``, or None when not given.
    twists : tuple of Twist
        The desired twists, possibly none.
    line : int
        1-based line where the document starts.
    paths : tuple of ObjectPath
        The object paths of its ``paths`` key, possibly none.
    hand : Hand or None
        The hand whose fingers touch the contacts, finger ``f`` contact ``f``.
    joint_positions : numpy.ndarray or None
        ``(n_joints,)`` the hand's configuration, in ``hand.joint_names``
        order (zeros for joints given inline, at their configuration); while
        ``placement`` is pending, what the file gives: the positions to check,
        or the seed to solve from.
    friction : numpy.ndarray or None
        ``(3,)`` Coulomb friction coefficient ``mu_i >= 0`` of each contact
        (a contact's own ``friction``, else the grasp's); None when not given.
    torsion : numpy.ndarray or None
        ``(3,)`` each contact's torsional radius ``e_i`` (a length): ``> 0`` for a
        contact given ``model: soft``, 0 for a point contact; None when every
        contact is a point contact.
    wrenches : tuple of Wrench
        The wrenches the fingers must exert, possibly none; the last is
        ``hold`` when ``mass`` is given.
    mass : float or None
        The object's mass, > 0.
    center_of_mass, gravity : numpy.ndarray or None
        ``(3,)`` each, given with ``mass`` (gravity by default
        ``(0, 0, -9.81)``); None without it.
    placement : HandPlacement or None
        A URDF hand not yet placed on the contacts, as the file gives it (the
        loader only reads: :func:`grasptwist.place_grasp` checks or
        solves the joint positions); None once placed, or for an inline hand.
    object : GraspObject or None
        The object the fingers hold, None when the file gives none.
    surface_distance : numpy.ndarray or None
        ``(3,)`` each given point's signed distance from the object's surface
        (> 0 outside) before it was put on it; None without an object.
    warnings : tuple of str
        Found when it was read (``rotation-over-pi``: its object's pose turned by a rotation
        vector over pi; ``normal-disagrees``: a given normal far from the object's surface normal),
        then when its hand was placed (``finger-collides``: a finger link inside the object;
        ``fingers-collide``: two fingers' links overlap; ``finger-hits-environment``: a finger
        within the clearance of the table or a box),
        carried into each of its records.
    environment : Environment or None
        The table and obstacles around the object (its ``environment``, or the command line's
        ``--table``); None: nothing around it.
    clearance : float or None
        With a table or a box: the least signed distance of any finger part (without a hand, of
        any contact) from them, found when the grasp was placed; None without.
    """

    name: str
    units: str | None
    file: str
    document: int
    contact_names: tuple[str, str, str]
    points: np.ndarray
    normals: np.ndarray
    wrist: np.ndarray | None
    twists: tuple[Twist, ...]
    line: int
    paths: tuple[ObjectPath, ...] = ()
    hand: Hand | None = None
    joint_positions: np.ndarray | None = None
    friction: np.ndarray | None = None
    torsion: np.ndarray | None = None
    wrenches: tuple[Wrench, ...] = ()
    mass: float | None = None
    center_of_mass: np.ndarray | None = None
    gravity: np.ndarray | None = None
    placement: HandPlacement | None = None
    object: GraspObject | None = None
    surface_distance: np.ndarray | None = None
    warnings: tuple[str, ...] = ()
    environment: Environment | None = None
    clearance: float | None = None


@dataclass(frozen=True, eq=False)
class Shape:
    """An object's shape in its own frame: a primitive centred at its origin, or a triangle mesh.

    Checked by :func:`grasptwist.objects.check_shape`; the geometry is in
    ``grasptwist.engine.objects``.

    Attributes
    ----------
    kind : str
        ``"box"``, ``"sphere"``, ``"cylinder"``, ``"capsule"`` or ``"mesh"``.
    size : numpy.ndarray
        A box's ``(3,)`` edge lengths ``a, b, c`` along x, y, z; a sphere's
        ``(1,)`` radius; a cylinder's ``(2,)`` radius and height (axis z); a
        capsule's ``(2,)`` radius and height, the distance between its two
        caps' centres (axis z: trimesh's convention); ``(0,)`` for a mesh.
    vertices : numpy.ndarray or None
        A mesh's ``(V, 3)`` float vertices, scale already applied; None for a primitive.
    faces : numpy.ndarray or None
        A mesh's ``(F, 3)`` int vertex indices of each triangle, counter-clockwise
        seen from outside; None for a primitive.
    source : str or None
        A mesh's file as the grasp file names it; None for a primitive.
    scale : numpy.ndarray or None
        A mesh's ``(1,)`` or ``(3,)`` factor from its file's coordinates to ``vertices`` (its own
        unit into the grasp file's, times ``scale``), so that a file written back names it; None: 1.
    """

    kind: str
    size: np.ndarray
    vertices: np.ndarray | None = None
    faces: np.ndarray | None = None
    source: str | None = None
    scale: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class GraspObject:
    """The object a grasp holds: its shape, where it is, and what it weighs.

    Attributes
    ----------
    shape : Shape
        In the object's own frame.
    pose : numpy.ndarray
        ``(4, 4)`` homogeneous rigid transform from the object's frame to the
        grasp's frame (the identity when the file gives no ``pose``).
    mass : float or None
        Its mass (kg), given or from ``density`` times its volume; None when
        neither is given.
    density : float or None
        Its density as given, in kg/m^3 (a grasp file's object's mass is then its
        density times its volume in cubic metres, through the file's ``units``); None when
        not given.  From Python, :func:`~grasptwist.objects.mass_properties` weighs
        ``density`` times the volume in the shape's own unit: metres, unless ``mass`` is given.
    line : int or None
        1-based line where the ``object`` key starts in the file.
    """

    shape: Shape
    pose: np.ndarray
    mass: float | None = None
    density: float | None = None
    line: int | None = None


@dataclass(frozen=True, eq=False)
class Segment:
    """One piece of an object path, held for ``duration``: a constant twist or a pose target.

    Poses are the object's rigid motion from its start, ``p -> R p + x``
    (identity at ``t = 0``), in the grasp frame.  Checked by
    :func:`grasptwist.path.check_segments`; the math is in
    ``grasptwist.engine.path``.

    Attributes
    ----------
    duration : float
        Time the segment lasts, > 0.
    twist : array-like of 6 or None
        A constant twist ``(omega; v)``; None for a pose target.
    frame : str
        The frame ``twist`` is given in: ``"space"`` (the fixed grasp frame;
        ``v`` the velocity of the point at the grasp frame's origin) or
        ``"body"`` (moving with the object, coincident with the grasp frame
        at ``t = 0``).
    position : array-like of 3 or None
        A pose target's position ``x``; None for a twist.
    rotation : array-like (3, 3) or None
        A pose target's rotation matrix ``R``; None for a twist.
    rotvec : array-like of 3 or None
        The rotation vector (radians) a pose target's ``R`` was given by, as
        written, and ``line``, ``column``, where (1-based): kept to judge its
        size (``grasptwist.engine.judgements.rotation_over_pi``).
    """

    duration: float
    twist: np.ndarray | None = None
    frame: str = "space"
    position: np.ndarray | None = None
    rotation: np.ndarray | None = None
    rotvec: np.ndarray | None = None
    line: int | None = None
    column: int | None = None


@dataclass(frozen=True, eq=False)
class ObjectPath:
    """A named object path of a grasp file: its segments, in order.

    Attributes
    ----------
    name : str
        Its ``name``, or ``"1"``, ``"2"``, ... by position in ``paths``.
    segments : tuple of Segment
        Checked by :func:`grasptwist.path.check_segments`.
    line : int or None
        1-based line of the path's entry in the file.
    """

    name: str
    segments: tuple[Segment, ...]
    line: int | None


class InputError(Exception):
    """An input (a grasp file or one document of it, a data set, a path, a URDF) that cannot be used.

    ``str(error)`` is one printable line, ``file:line:column: message``
    (``:line:column`` left out when unknown).  0.5 and before called it ``GraspFileError``,
    a deprecated alias now (``grasptwist.GraspFileError`` warns).

    Attributes
    ----------
    code : str
        Stable kebab-case code, one of ``grasptwist.codes.ERRORS`` (documented in
        docs/reference/bad-input-and-faults.md, "Every code").
    message : str
        What is wrong, starting with the field path when there is one.
    file : str
    line, column : int or None
        1-based position.
    document : int or None
        0-based document index; None for whole-file errors.
    problems : tuple of InputError
        Every problem of the input, this error (its first) included: one
        record per failed document lists them all.
    """

    code: str
    message: str
    file: str
    line: int | None
    column: int | None
    document: int | None
    problems: tuple

    def __init__(self, code, message, file, line=None, column=None, document=None, problems=None):
        # All fields go to args so that errors pickle (multiprocessing).
        super().__init__(code, message, file, line, column, document, problems)
        self.code = code
        self.message = message
        self.file = file
        self.line = line
        self.column = column
        self.document = document
        self.problems = (self,) if problems is None else tuple(problems)

    def __str__(self):
        where = self.file
        if self.line is not None:
            where += f":{self.line}"
            if self.column is not None:
                where += f":{self.column}"
        return f"{where}: {self.message}"


#: The names of the submodules' types -> their module, imported when first asked for.
_ELSEWHERE = {
    "Obstacle": ".environment",
    "Environment": ".environment",
    "HandPlacement": ".hands",
    "Joint": ".hands",
    "Finger": ".hands",
    "Hand": ".hands",
}


def __getattr__(name: str):
    if name in _ELSEWHERE:
        from importlib import import_module

        return getattr(import_module(_ELSEWHERE[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
