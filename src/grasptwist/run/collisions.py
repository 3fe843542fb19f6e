"""Fingers through the object, into each other and into the world around it: which parts of a placed hand, how deep.

With a URDF hand and an object, every finger link's collision geometry
(:func:`~grasptwist.io.urdf_meshes.link_geometry`) is checked against the
object (:func:`~grasptwist.engine.collision.penetration_depths`) at the
grasp (:mod:`.placement`) and at every path sample (:mod:`.follow`); a link
deeper than :func:`~grasptwist.engine.collision.collision_tolerance` (0.1 %
of the object's size) is a :class:`Collision`, a warning ``finger-collides``
in its record and one line on stderr.  The fingertip's sphere (the tip
link's vertices within ``tip_radius`` plus that tolerance of its origin) is
the contact itself and left out.

The fingers are checked against each other too (their links' convex hulls and their
fingertip spheres, :func:`~grasptwist.engine.collision.finger_overlaps`): two parts of
different fingers deeper than that tolerance into each other are an :class:`Overlap`,
``fingers-collide``; and against the grasp's environment (a table, boxes): a part nearer
than the clearance is an :class:`EnvironmentHit`, ``finger-hits-environment``
(:func:`~grasptwist.engine.environment.parts_distance`; without a hand, the contacts
themselves, as points).  :func:`hand_constraints` builds the same checks for the search.
No math here.
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np

from ..engine.collision import (
    clusters,
    collision_tolerance,
    finger_overlaps,
    link_hulls,
    link_poses,
    penetration_depths,
    tip_centers_at,
    tip_sphere,
)
from ..engine.environment import clearance_of, has_obstacles, needs_checks, obstacle_name, parts_distance
from ..engine.fingertips import tip_radii
from ..engine.placement import home_at
from ..io.limits import MAX_URDF_BYTES
from ..io.urdf_meshes import grasp_folder, link_geometry
from ..model import Grasp, InputError
from ..output.names import escaped

__all__ = [
    "CODE",
    "CODES",
    "FINGERS_CODE",
    "ENVIRONMENT_CODE",
    "Collision",
    "Overlap",
    "EnvironmentHit",
    "collision_warning",
    "overlap_warning",
    "environment_warning",
    "finger_collisions",
    "finger_collisions_along",
    "hand_checks_along",
    "hand_constraints",
    "hand_error",
    "with_collisions",
    "PathCollisions",
]

#: The warnings' codes: a link in the object, two fingers into each other, a finger too near the environment.
CODE, FINGERS_CODE, ENVIRONMENT_CODE = "finger-collides", "fingers-collide", "finger-hits-environment"
CODES = (CODE, FINGERS_CODE, ENVIRONMENT_CODE)


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


class Overlap(NamedTuple):
    """Two fingers into each other: a part of each (a link, or a fingertip sphere named by its tip link) and how deep."""

    finger: str
    link: str
    other_finger: str
    other_link: str
    depth: float


class EnvironmentHit(NamedTuple):
    """A finger's part nearer the environment than the clearance.

    Attributes
    ----------
    finger, link : str
        The finger (its contact's name) and its part: a link, its tip link's sphere; without a
        hand the contact's name and None (the contact point itself).
    obstacle : str
        ``the table`` or ``box k``.
    distance : float
        Its signed distance from the obstacle (< 0: that deep into it).
    clearance : float
        The clearance it should keep.
    """

    finger: str
    link: str | None
    obstacle: str
    distance: float
    clearance: float


def collision_warning(c: Collision) -> str:
    """The warning, one line, for records and stderr.

    >>> collision_warning(Collision("1", "finger_middle_link_0", 0.0042))
    "finger-collides: finger 1's link 'finger_middle_link_0' is 0.0042 inside the object"
    """
    return f"{CODE}: finger {escaped(c.finger)}'s link {escaped(c.link)!r} is {c.depth:.3g} inside the object"


def overlap_warning(o: Overlap) -> str:
    """The warning of two fingers into each other.

    >>> overlap_warning(Overlap("0", "finger_lower_link_0", "120", "finger_tip_link_120", 0.0038))
    "fingers-collide: finger 0's link 'finger_lower_link_0' and finger 120's link 'finger_tip_link_120' overlap by 0.0038"
    """
    return (
        f"{FINGERS_CODE}: finger {escaped(o.finger)}'s link {escaped(o.link)!r} and finger "
        f"{escaped(o.other_finger)}'s link {escaped(o.other_link)!r} overlap by {o.depth:.3g}"
    )


def environment_warning(h: EnvironmentHit) -> str:
    """The warning of a finger too near the environment (its depth into it, or its distance from it).

    >>> environment_warning(EnvironmentHit("0", "finger_tip_link_0", "the table", -0.0042, 0.001))
    "finger-hits-environment: finger 0's link 'finger_tip_link_0' is 0.0042 into the table (clearance 0.001)"
    >>> environment_warning(EnvironmentHit("2", None, "box 1", 0.0004, 0.001))  # a contact, without a hand
    'finger-hits-environment: contact 2 is 0.0004 from box 1, within the clearance 0.001'
    """
    part = (
        f"contact {escaped(h.finger)}" if h.link is None else f"finger {escaped(h.finger)}'s link {escaped(h.link)!r}"
    )
    where = f"{ENVIRONMENT_CODE}: {part} is"
    if h.distance < 0:
        return f"{where} {-h.distance:.3g} into {h.obstacle} (clearance {h.clearance:.3g})"
    return f"{where} {h.distance:.3g} from {h.obstacle}, within the clearance {h.clearance:.3g}"


#: The last hands' link geometry, and their clusters by tip radii and tolerance: a folder's grasps name
#: the same URDF (each its own Hand), a path's samples the same grasp.  Bounded: a few of each.
_GEOMETRY: dict = {}
_CLUSTERS: dict = {}
_HULLS: dict = {}


def _kept(cache, key, make):
    if key not in cache:
        if len(cache) >= 8:
            del cache[next(iter(cache))]
        cache[key] = make()
    return cache[key]


def _geometry(hand, folder, max_bytes):
    """The finger links of a URDF hand (cached) and the key they are kept under; None for an inline hand."""
    if hand is None or hand.source is None:
        return None
    key = (hand.source, folder, max_bytes, tuple(tuple(j.name for j in f.joints) for f in hand.fingers))
    return _kept(_GEOMETRY, key, lambda: link_geometry(hand, folder=folder, max_bytes=max_bytes)), key


def _checked(hand, obj, folder, max_bytes):
    """The finger links, their vertices in clusters with the fingertip spheres left out, and the
    tolerance; None when there is nothing to check."""
    found = None if obj is None else _geometry(hand, folder, max_bytes)
    if found is None:
        return None
    geometry, key = found
    tol = collision_tolerance(obj)

    def cut():
        kept = []
        for g in geometry:
            f = hand.fingers[g.finger]
            on_sphere = tip_sphere(g.vertices, f.tip_pose[:3, 3], f.tip_radius, tol) & (g.link == f.tip)
            kept.append(g.vertices[~on_sphere])
        return clusters(kept)

    parts = _kept(_CLUSTERS, (key, tuple(f.tip_radius for f in hand.fingers), tol), cut)
    return geometry, parts, tol


def _hulls(hand, folder, max_bytes):
    """The finger links' convex hulls of a URDF hand (cached; none for an inline hand)."""
    found = _geometry(hand, folder, max_bytes)
    if found is None:
        return link_hulls(())
    return _kept(_HULLS, found[1], lambda: link_hulls(found[0]))


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
    checked = _checked(grasp.hand, grasp.object, grasp_folder(grasp), max_bytes)
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


def hand_constraints(
    obj, hand, *, environment=None, clearance=None, tips=None, tip_radius=None, folder=None, max_bytes=MAX_URDF_BYTES
):
    """A hand as the synthesis search takes it, with every check the command line makes.

    Its fingertips on the surface and within their joint limits, and at every grasp no finger
    link (a URDF's collision meshes) in the object, no two fingers into each other (their
    links' convex hulls and fingertip spheres), every part of the hand ``clearance`` from the
    ``environment`` (``grasptwist.synthesize``'s default; the search's ``hand``).

    Parameters
    ----------
    obj : GraspObject
    hand : Hand
        Three fingers that share no joint, in the grasp frame.
    environment : Environment, optional
        A table and boxes.
    clearance : float, optional
        Default the environment's, else ``grasptwist.engine.environment.CLEARANCE``.
    tips, tip_radius
        Each finger's tip link pose at home (needed for a finger given inline), every fingertip's
        radius (default each finger's ``tip_radius``).
    folder : str or os.PathLike, optional
        The folder a URDF hand's relative paths are found from (its grasp file's).
    max_bytes : int
        Size cap of the URDF.

    Returns
    -------
    HandReach

    Raises
    ------
    InputError
        The URDF's or a mesh's, read here once.
    ValueError
        A hand that is not three fingers sharing no joint.

    Examples
    --------
    >>> import grasptwist as gt
    >>> (g,) = gt.read_grasps("grasps/trifinger-cube.yaml")
    >>> reach = hand_constraints(g.object, g.hand, environment=g.environment, folder="grasps")
    >>> len(reach.hulls.links), reach.environment.table_height, reach.clearance
    (12, 0.0, 0.001)
    """
    from ..engine.synthesis.problem import hand_reach  # the search's: with the first one asked for

    checked = _checked(hand, obj, folder, max_bytes)
    collide = None
    if checked is not None:
        geometry, parts, _ = checked

        def collide(positions):
            poses = link_poses(hand, geometry, np.asarray(positions, dtype=float))
            return penetration_depths(obj, parts, poses, len(geometry)).max(axis=1, initial=0.0)

    hulls = _hulls(hand, folder, max_bytes)
    return hand_reach(
        obj,
        hand,
        tips=tips,
        tip_radius=tip_radius,
        collide=collide,
        hulls=hulls,
        environment=environment,
        clearance=clearance,
    )


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
        Each link deeper than ``grasptwist.engine.collision.COLLISION_TOL`` times the object's size, naming its
        finger, link and depth; the fingertip spheres touching their contacts are no collision
        (docs/guide/hands.md, "Fingers through the object").

    Raises
    ------
    InputError
        The URDF's or a mesh's, as :func:`~grasptwist.place_grasp` reports them.

    Examples
    --------
    >>> import grasptwist as gt
    >>> g = gt.place_grasp(gt.read_grasps("grasps/trifinger-cube.yaml")[0])
    >>> finger_collisions(g, g.joint_positions)  # the fingertips touch the cube, nothing else does
    ()
    """
    return finger_collisions_along(grasp, np.asarray(joint_positions, dtype=float)[None])[0]


def _parts(grasp, max_bytes):
    """What the fingers are made of: the links' hulls, each finger's tip pose at home, the fingertip
    radii and each part's ``(finger, link)`` names (links, then spheres)."""
    hand, names = grasp.hand, grasp.contact_names
    hulls = _hulls(hand, grasp_folder(grasp), max_bytes)
    radii = tip_radii(hand)
    # an inline hand is at home where its file gives it: its tip points on the contacts' sphere centres
    tips = home_at(hand, grasp.points, grasp.normals)
    labels = [(names[g.finger], g.link) for g in hulls.links]
    labels += [(names[f], finger.tip or "fingertip") for f, finger in enumerate(hand.fingers)]
    return hulls, tips, radii, labels


def hand_checks_along(grasp: Grasp, *, joint_positions=None, max_bytes=MAX_URDF_BYTES):
    """Per configuration, the fingers into each other and too near the environment, and the clearance.

    Parameters
    ----------
    grasp : Grasp
        A hand's fingers are checked against each other (a URDF hand's links and the fingertip
        spheres; an inline hand's spheres), and with an environment every part against it;
        without a hand, the contacts (points) against the environment.
    joint_positions : (N, n_joints) array, optional
        Default: the grasp's.

    Returns
    -------
    overlaps : list of tuple of Overlap
        Deepest first, one tuple per configuration.
    hits : list of tuple of EnvironmentHit
        Nearest first.
    clearance : (N,) array or None
        The least signed distance of any part from the environment; None without one.

    Raises
    ------
    InputError
        The URDF's or a mesh's.

    Examples
    --------
    >>> import grasptwist as gt
    >>> g = gt.place_grasp(gt.read_grasps("grasps/trifinger-cube.yaml")[0])
    >>> overlaps, hits, clearance = hand_checks_along(g)
    >>> overlaps, hits, clearance.round(4).tolist()  # its lowest fingertip sphere is 5 mm above the table
    ([()], [()], [0.005])
    """
    env = grasp.environment
    if grasp.hand is None:  # the contacts, as points
        overlaps, hits = [()], [()]
        poses, centers, radii = np.zeros((1, 0, 4, 4)), np.asarray(grasp.points, float)[None], np.zeros(3)
        hulls, labels = link_hulls(()), [(name, None) for name in grasp.contact_names]
    else:
        q = np.asarray(grasp.joint_positions if joint_positions is None else joint_positions, dtype=float)
        q = q.reshape(-1, q.shape[-1])
        overlaps, hits = [()] * len(q), [()] * len(q)
        hulls, tips, radii, labels = _parts(grasp, max_bytes)
        poses, centers = link_poses(grasp.hand, hulls.links, q), tip_centers_at(grasp.hand, tips, q)
        tol = 0.0 if grasp.object is None else collision_tolerance(grasp.object)
        depth = finger_overlaps(hulls, poses, centers, radii)
        overlaps = [_overlaps(d, tol, labels) for d in depth]
    if not has_obstacles(env):
        return overlaps, hits, None
    room = clearance_of(env)
    distance, nearest = parts_distance(hulls.parts, len(hulls.links), poses, centers, radii, env)
    for i, (d, k) in enumerate(zip(distance, nearest)):
        near = np.flatnonzero(d < room)
        near = near[np.argsort(d[near], kind="stable")]
        found = (EnvironmentHit(*labels[j], obstacle_name(int(k[j])), float(d[j]), room) for j in near)
        hits[i] = _first(found, lambda h: h[:2])
    return overlaps, hits, distance.min(axis=1)


def _overlaps(depth, tol, labels):
    """The pairs of parts deeper than ``tol`` into each other, deepest first."""
    a, b = np.nonzero(np.triu(depth > tol, 1))
    order = np.argsort(-depth[a, b], kind="stable")
    found = (Overlap(*labels[i], *labels[j], float(depth[i, j])) for i, j in zip(a[order], b[order]))
    return _first(found, lambda o: o[:4])


def _first(found, key) -> tuple:
    """The first of each part named alike (a tip link's hull and its fingertip sphere share the tip link's name)."""
    seen = {}
    for item in found:
        seen.setdefault(key(item), item)
    return tuple(seen.values())


def with_collisions(grasp: Grasp) -> Grasp | InputError:
    """A placed grasp with a warning per link inside its object (``finger-collides``), per pair of
    fingers into each other (``fingers-collide``) and per part too near its environment
    (``finger-hits-environment``), and its ``clearance`` from that environment; or the error of its
    hand's meshes (read from its URDF for the check).

    Examples
    --------
    >>> import grasptwist as gt
    >>> g = gt.place_grasp(gt.read_grasps("grasps/trifinger-cube.yaml")[0])  # checked there
    >>> g.warnings
    ()
    """
    if not needs_checks(grasp.hand, grasp.environment):
        return grasp
    try:
        found = finger_collisions(grasp, grasp.joint_positions) if grasp.hand is not None else ()
        overlaps, hits, clearance = hand_checks_along(grasp)
    except InputError as exc:
        return hand_error(exc, grasp)
    said = (
        *(collision_warning(c) for c in found),
        *(overlap_warning(o) for o in overlaps[0]),
        *(environment_warning(h) for h in hits[0]),
    )
    said = tuple(w for w in said if w not in grasp.warnings)  # a grasp placed twice is warned once
    least = None if clearance is None else float(clearance[0])
    if not said and least == grasp.clearance:
        return grasp
    return replace(grasp, warnings=grasp.warnings + said, clearance=least)


def hand_error(exc: InputError, grasp: Grasp, hand=None) -> InputError:
    """The error of a URDF hand's meshes (read after the hand, for its checks) where the file that names
    the URDF says it: at ``hand``'s ``urdf`` key (``hand.urdf_at``: the grasp file's, or ``--hand``'s),
    the URDF's file and its ``<mesh>``'s line in the message; at ``grasp``'s document for a hand
    read elsewhere (Python).  ``hand``: default the grasp's.

    >>> import grasptwist as gt
    >>> (g,) = gt.read_grasps("grasps/trifinger-cube.yaml")
    >>> str(hand_error(InputError("read-error", "mesh 'a.stl': cannot read", "t.urdf", 9), g))
    "grasps/trifinger-cube.yaml:40:9: hand.urdf: t.urdf:9: mesh 'a.stl': cannot read"
    """
    at = (grasp.hand if hand is None else hand).urdf_at
    if at is None:
        return InputError(exc.code, f"hand: {exc}", grasp.file, grasp.line, None, grasp.document)
    file, line, column = at
    return InputError(exc.code, f"hand.urdf: {exc}", file, line, column, grasp.document if file == grasp.file else None)


class PathCollisions:
    """The collisions along one path of a grasp, chunk by chunk of its samples: each sample's
    records get their warnings, the path's summary one line per link that went into the object,
    per pair of fingers that went into each other and per part that came too near the environment."""

    def __init__(self, grasp: Grasp):
        self.grasp = grasp
        self.seen = {}  # (code, names) -> [worst, samples, first time, clearance]

    def at(self, positions, poses) -> tuple[list | None, np.ndarray | None]:
        """Each sample's warnings at joint ``positions`` and object ``poses``
        (:class:`~grasptwist.engine.path.Poses`), None when none has any (the block's ``grasp_warnings``),
        and each sample's clearance from the environment (None without one, or without a hand)."""
        if positions is None or not needs_checks(self.grasp.hand, self.grasp.environment):
            return None, None
        frames = np.zeros((len(poses.time), 4, 4))
        frames[:, :3, :3], frames[:, :3, 3], frames[:, 3, 3] = poses.rotation, poses.position, 1.0
        inside = finger_collisions_along(self.grasp, positions, frames)
        # the hand and the environment stay where they are: the object moves between them
        overlaps, hits, clearance = hand_checks_along(self.grasp, joint_positions=positions)
        said = []
        for time, a, b, c in zip(poses.time.tolist(), inside, overlaps, hits):
            for hit in a:
                self._saw((CODE, hit.finger, hit.link), hit.depth, time, max)
            for o in b:
                self._saw((FINGERS_CODE, o.finger, o.link, o.other_finger, o.other_link), o.depth, time, max)
            for h in c:
                self._saw((ENVIRONMENT_CODE, h.finger, h.link, h.obstacle, h.clearance), h.distance, time, min)
            said.append((*map(collision_warning, a), *map(overlap_warning, b), *map(environment_warning, c)))
        return (said if any(said) else None), clearance

    def _saw(self, key, value, time, worse):
        seen = self.seen.setdefault(key, [value, 0, time])
        seen[0], seen[1] = worse(seen[0], value), seen[1] + 1

    def warnings(self, samples: int) -> tuple[str, ...]:
        """The summary's lines, one per link that went into the object, deepest first, then the fingers
        into each other and the parts too near the environment.

        >>> along = PathCollisions(None)
        >>> along.seen[("finger-collides", "1", "finger_lower_link_0")] = [0.0042, 3, 0.5]
        >>> along.seen[("finger-hits-environment", "1", "finger_tip_link_0", "the table", 0.001)] = [-0.002, 2, 1.0]
        >>> for line in along.warnings(21):
        ...     print(line)
        finger-collides: finger 1's link 'finger_lower_link_0' goes up to 0.0042 inside the object at 3 of 21 samples, from t = 0.5
        finger-hits-environment: finger 1's link 'finger_tip_link_0' comes to -0.002 from the table (clearance 0.001) at 2 of 21 samples, from t = 1
        """
        lines = []
        for code in (CODE, FINGERS_CODE, ENVIRONMENT_CODE):
            mine = [(key, v) for key, v in self.seen.items() if key[0] == code]
            mine.sort(key=lambda item: item[1][0] if code == ENVIRONMENT_CODE else -item[1][0])
            for key, (worst, count, first) in mine:
                lines.append(f"{_along(key, worst)} at {count} of {samples} samples, from t = {first:.6g}")
        return tuple(lines)


def _along(key, worst) -> str:
    """The start of a summary line: what went where along the path, at worst."""
    code, finger, link, *rest = key
    part = (
        f"{code}: finger {escaped(finger)}'s link {escaped(link)!r}" if link else f"{code}: contact {escaped(finger)}"
    )
    if code == CODE:
        return f"{part} goes up to {worst:.3g} inside the object"
    if code == FINGERS_CODE:
        return f"{part} and finger {escaped(rest[0])}'s link {escaped(rest[1])!r} overlap by up to {worst:.3g}"
    return f"{part} comes to {worst:.3g} from {rest[0]} (clearance {rest[1]:.3g})"
