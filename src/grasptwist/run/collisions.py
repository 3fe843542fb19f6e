"""Fingers through the object: which links of a placed hand go into it, and how deep.

With a URDF hand and an object, every finger link's collision geometry
(:func:`~grasptwist.io.urdf_meshes.link_geometry`) is checked against the
object (:func:`~grasptwist.engine.collision.penetration_depths`) at the
grasp (:mod:`.placement`) and at every path sample (:mod:`.follow`); a link
deeper than :func:`~grasptwist.engine.collision.collision_tolerance` (0.1 %
of the object's size) is a :class:`Collision`, a warning ``finger-collides``
in its record and one line on stderr.  The fingertip's sphere (the tip
link's vertices within ``tip_radius`` plus that tolerance of its origin) is
the contact itself and left out.  No math here.
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np

from ..engine.collision import clusters, collision_tolerance, link_poses, penetration_depths, tip_sphere
from ..io.limits import MAX_URDF_BYTES
from ..io.urdf_meshes import grasp_folder, link_geometry
from ..model import Grasp, GraspFileError, InputError
from ..output.names import escaped

__all__ = [
    "CODE",
    "Collision",
    "collision_warning",
    "finger_collisions",
    "finger_collisions_along",
    "deepest_link",
    "with_collisions",
    "PathCollisions",
]

#: The warning's code.
CODE = "finger-collides"


class Collision(NamedTuple):
    """A finger link inside the object.

    Attributes
    ----------
    finger : str
        The finger's name: its contact's (as every message names fingers).
    link : str
        The link's name in the URDF.
    depth : float
        How deep its deepest vertex is inside the object (grasp units), above the tolerance.
    """

    finger: str
    link: str
    depth: float


def collision_warning(c: Collision) -> str:
    """The warning, one line, for records and stderr.

    >>> collision_warning(Collision("1", "finger_middle_link_0", 0.0042))
    "finger-collides: finger 1's link 'finger_middle_link_0' is 0.0042 inside the object"
    """
    return f"{CODE}: finger {escaped(c.finger)}'s link {escaped(c.link)!r} is {c.depth:.3g} inside the object"


#: The last hands' link geometry, and their clusters by tip radii and tolerance: a folder's grasps name
#: the same URDF (each its own Hand), a path's samples the same grasp.  Bounded: a few of each.
_GEOMETRY: dict = {}
_CLUSTERS: dict = {}


def _kept(cache, key, make):
    if key not in cache:
        if len(cache) >= 8:
            del cache[next(iter(cache))]
        cache[key] = make()
    return cache[key]


def _checked(grasp, max_bytes):
    """The finger links, their vertices in clusters with the fingertip spheres left out, and the
    tolerance; None when there is nothing to check."""
    hand = grasp.hand
    if grasp.object is None or hand is None or hand.source is None:
        return None
    folder = grasp_folder(grasp)
    key = (hand.source, folder, max_bytes, tuple(tuple(j.name for j in f.joints) for f in hand.fingers))
    geometry = _kept(_GEOMETRY, key, lambda: link_geometry(hand, folder=folder, max_bytes=max_bytes))
    tol = collision_tolerance(grasp.object)

    def cut():
        kept = []
        for g in geometry:
            f = hand.fingers[g.finger]
            on_sphere = tip_sphere(g.vertices, f.tip_pose[:3, 3], f.tip_radius, tol) & (g.link == f.tip)
            kept.append(g.vertices[~on_sphere])
        return clusters(kept)

    parts = _kept(_CLUSTERS, (key, tuple(f.tip_radius for f in hand.fingers), tol), cut)
    return geometry, parts, tol


def finger_collisions_along(grasp: Grasp, joint_positions, frames=None, *, max_bytes=MAX_URDF_BYTES):
    """Per configuration, the links of ``grasp``'s hand inside its object.

    Parameters
    ----------
    grasp : Grasp
        With a URDF hand and an object (else no collisions).
    joint_positions : (N, n_joints) array
    frames : (N, 4, 4) array, optional
        The object's motion at each configuration (a path's poses); None: where the grasp has it.
    max_bytes : int
        Size cap of the URDF.

    Returns
    -------
    list of tuple of Collision
        One tuple per configuration, deepest first.

    Raises
    ------
    InputError
        The URDF's or a mesh's (:func:`~grasptwist.io.urdf_meshes.link_geometry`).
    """
    q = np.asarray(joint_positions, dtype=float)
    checked = _checked(grasp, max_bytes)
    if checked is None:
        return [()] * len(q)
    geometry, parts, tol = checked
    depth = penetration_depths(grasp.object, parts, link_poses(grasp.hand, geometry, q, frames), len(geometry))
    names = grasp.contact_names
    out = []
    for row in depth:
        hits = np.flatnonzero(row > tol)
        hits = hits[np.argsort(-row[hits], kind="stable")]
        out.append(tuple(Collision(names[geometry[i].finger], geometry[i].link, float(row[i])) for i in hits))
    return out


def deepest_link(grasp: Grasp, *, max_bytes=MAX_URDF_BYTES):
    """How deep the deepest finger link of ``grasp``'s hand goes into its object, as a function of
    joint positions ``(N, n_joints) -> (N,)`` (the synthesis search's collision constraint); None
    without a URDF hand or an object.

    Raises
    ------
    InputError
        The URDF's or a mesh's, read here once.
    """
    checked = _checked(grasp, max_bytes)
    if checked is None:
        return None
    geometry, parts, _ = checked

    def deepest(positions):
        poses = link_poses(grasp.hand, geometry, np.asarray(positions, dtype=float))
        return penetration_depths(grasp.object, parts, poses, len(geometry)).max(axis=1, initial=0.0)

    return deepest


def finger_collisions(grasp: Grasp, joint_positions) -> tuple[Collision, ...]:
    """The links of ``grasp``'s hand inside its object at ``joint_positions``, deepest first.

    Parameters
    ----------
    grasp : Grasp
        With a URDF hand and an object (else none); the object where the grasp has it.
    joint_positions : (n_joints,) array
        In ``grasp.hand.joint_names`` order.

    Returns
    -------
    tuple of Collision
        Each link deeper than :data:`~grasptwist.hand.COLLISION_TOL` times the object's size, naming its
        finger, link and depth; the fingertip spheres touching their contacts are no collision
        (docs/guide/hands.md, "Fingers through the object").

    Raises
    ------
    InputError
        The URDF's or a mesh's, as :func:`~grasptwist.hand.place_grasp` reports them.

    Examples
    --------
    >>> import grasptwist as gt
    >>> g = gt.hand.place_grasp(gt.read_grasps("grasps/trifinger-cube.yaml")[0])
    >>> finger_collisions(g, g.joint_positions)  # the fingertips touch the cube, nothing else does
    ()
    """
    return finger_collisions_along(grasp, np.asarray(joint_positions, dtype=float)[None])[0]


def with_collisions(grasp: Grasp) -> Grasp | GraspFileError:
    """A placed grasp with a ``finger-collides`` warning per link inside its object (none without an
    object), or the error of its hand's meshes (read from its URDF for the check).

    Examples
    --------
    >>> import grasptwist as gt
    >>> g = gt.hand.place_grasp(gt.read_grasps("grasps/trifinger-cube.yaml")[0])  # checked there
    >>> g.warnings
    ()
    """
    try:
        found = finger_collisions(grasp, grasp.joint_positions)
    except InputError as exc:
        return GraspFileError(exc.code, f"hand: {exc.message}", grasp.file, grasp.line, None, grasp.document)
    if not found:
        return grasp
    return replace(grasp, warnings=grasp.warnings + tuple(collision_warning(c) for c in found))


class PathCollisions:
    """The collisions along one path of a grasp, chunk by chunk of its samples: each sample's
    records get their warnings, the path's summary one line per link that went into the object."""

    def __init__(self, grasp: Grasp):
        self.grasp = grasp
        self.seen = {}  # (finger, link) -> [deepest, samples, first time]

    def at(self, positions, poses) -> list | None:
        """Each sample's warnings at joint ``positions`` and object ``poses``
        (:class:`~grasptwist.engine.path.Poses`), None when none has any (the block's ``grasp_warnings``)."""
        if positions is None or self.grasp.object is None:
            return None
        frames = np.zeros((len(poses.time), 4, 4))
        frames[:, :3, :3], frames[:, :3, 3], frames[:, 3, 3] = poses.rotation, poses.position, 1.0
        found = finger_collisions_along(self.grasp, positions, frames)
        for time, hits in zip(poses.time.tolist(), found):
            for c in hits:
                seen = self.seen.setdefault((c.finger, c.link), [0.0, 0, time])
                seen[0], seen[1] = max(seen[0], c.depth), seen[1] + 1
        return [tuple(map(collision_warning, hits)) for hits in found] if any(found) else None

    def warnings(self, samples: int) -> tuple[str, ...]:
        """The summary's lines, one per link that went into the object, deepest first.

        >>> along = PathCollisions(None)
        >>> along.seen[("1", "finger_lower_link_0")] = [0.0042, 3, 0.5]
        >>> along.warnings(21)
        ("finger-collides: finger 1's link 'finger_lower_link_0' goes up to 0.0042 inside the object at 3 of 21 samples, from t = 0.5",)
        """
        ranked = sorted(self.seen.items(), key=lambda item: -item[1][0])
        return tuple(
            f"{CODE}: finger {escaped(finger)}'s link {escaped(link)!r} goes up to {depth:.3g} inside the object "
            f"at {count} of {samples} samples, from t = {first:.6g}"
            for (finger, link), (depth, count, first) in ranked
        )
