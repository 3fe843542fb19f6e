r"""A hand's reach as constraints of the search: fingertips on the surface, joints within limits, no collision.

A candidate ``(p, n)`` is reachable by a hand when some assignment of its fingers to
the contacts (the TriFinger code's way: every permutation tried) passes, finger by
finger and then as a whole:

1. **fingertips** (``fingertips``): finger ``f``'s sphere of radius ``r_f``, centred at

   .. math:: c = p - r_f \hat n

   (one radius out of the object along its inward normal), stays outside the object:
   the signed distance of ``c`` is at least ``r_f - tol`` (``tol`` the collision
   tolerance, :data:`~grasptwist.engine.collision.COLLISION_TOL` times the object's
   size), so the sphere touches the surface at ``p`` and goes in nowhere else;
2. **reach** (``reach``): joint positions within the limits put the finger's tip point
   (its tip link's origin, the sphere's centre) on ``c``, to the inverse kinematics'
   tolerance (:func:`~grasptwist.engine.ik.finger_ik`); a centre farther from the
   finger's first joint than the finger is long is out of reach without solving;
3. **collision** (``collision``): at those positions no finger link goes deeper into
   the object than ``tol`` (a function of the joint positions the caller gives, as
   :mod:`grasptwist.run.collisions` builds it from the hand's meshes), no part of one
   finger goes deeper than ``tol`` into another finger's (their links' convex hulls and
   fingertip spheres, :func:`~grasptwist.engine.collision.finger_overlaps`), and every part
   keeps the ``clearance`` from the environment
   (:func:`~grasptwist.engine.environment.parts_distance`): :func:`violations`.

With an environment, a fingertip sphere must keep its clearance from it in the first test
too (``fingertips``), before any inverse kinematics.

The six assignments are tried nearest first (the least total distance from each finger's
first joint to its target: a finger reaching around the object to a far contact is the one
whose links go through it), the first that reaches and is clear of collisions kept.  The
nine (finger, contact) pairs of a candidate are solved at most once each, in two batches over
every candidate, all fingers in one (:func:`~grasptwist.engine.ik.fingers_ik`): first the
three pairs of each candidate's nearest assignment (which holds most candidates), then every
pair of the candidates it does not hold; each batch's assignments that reach are checked for
collisions in one call.  The assignment kept is the one an exhaustive solve of all nine pairs
would keep.  Fingers must not share joints (each finger's inverse kinematics is its own).
"""

from __future__ import annotations

from collections.abc import Callable
from itertools import permutations
from typing import NamedTuple

import numpy as np

from ..collision import LinkHulls, finger_overlaps, link_hulls, link_poses, tip_centers_at
from ..degeneracy import Status
from ..environment import has_obstacles, parts_distance, sphere_distance
from ..ik import IK_TOL, fingers_ik
from ..kinematics import forward_kinematics

__all__ = [
    "HAND_CONSTRAINTS",
    "IK_RESTARTS",
    "HandReach",
    "Reached",
    "check_hand_reach",
    "hand_clearance",
    "reach",
    "reach_tolerance",
    "tip_errors",
    "violations",
]

#: The hand's constraints in the order they are tested (after the grip: the inverse kinematics
#: is the search's most expensive test, so it runs on the fewest rows).
HAND_CONSTRAINTS = ("fingertips", "reach", "collision")

#: Spread seeds a (finger, contact) pair that misses from home starts again from: a search has
#: many candidates, so a pair the first seeds miss is given up rather than chased.
IK_RESTARTS = 2

#: Finger f's contact in each assignment, and the shift ``(contact - f) mod 3`` it reads.
_ORDERS = np.array(list(permutations(range(3))))
_SHIFTS = (_ORDERS - np.arange(3)) % 3


class HandReach(NamedTuple):
    """A hand as the search needs it (in the grasp frame).

    Attributes
    ----------
    hand : Hand
    tips : (3, 4, 4) array
        Each finger's tip link pose at home (:func:`~grasptwist.engine.ik.home_tips`).
    radii : (3,) array
        Each finger's fingertip radius.
    project : callable
        The object's ``project(points (..., 3)) -> (points, normals, distance)``.
    tolerance : float
        Depths (of a link, or of a fingertip sphere) at most this are no collision.
    collide : callable or None
        ``collide(positions (N, n_joints)) -> (N,)`` the deepest any link goes into the
        object; None: no link geometry to check.
    hulls : LinkHulls or None
        The finger links' convex hulls (:func:`~grasptwist.engine.collision.link_hulls`), checked
        against each other and the environment; None: the fingertip spheres alone.
    environment : Environment or None
        The table and boxes the fingers keep ``clearance`` from.
    clearance : float
    """

    hand: object
    tips: np.ndarray
    radii: np.ndarray
    project: Callable
    tolerance: float
    collide: Callable | None = None
    hulls: LinkHulls | None = None
    environment: object = None
    clearance: float = 0.0


class Reached(NamedTuple):
    """The hand on ``N`` candidates.

    Attributes
    ----------
    failed : (N,) int8
        The first of :data:`HAND_CONSTRAINTS` no assignment passes, -1 where one passes all.
    order : (N, 3) int
        Finger ``f`` touches contact ``order[:, f]`` (identity where none passes).
    positions : (N, n_joints)
        Joint positions of the assignment kept (NaN where none).
    miss : (N,)
        How close a failing row came: for ``reach``, its best assignment's largest distance
        from a tip point to its target; for ``collision``, its least :func:`violations`; NaN else.
    """

    failed: np.ndarray
    order: np.ndarray
    positions: np.ndarray
    miss: np.ndarray


def check_hand_reach(hand_reach: HandReach) -> HandReach:
    """A :class:`HandReach` whose fingers are three and share no joint.

    >>> from grasptwist.hand import Finger, Hand
    >>> f = Finger("a", None, (), None, None, None, 1.0, (0,))
    >>> check_hand_reach(HandReach(Hand((f, f, f), ("j",), None, None), None, None, None, 0.0))
    Traceback (most recent call last):
    ValueError: a hand searched over must have three fingers that share no joint
    """
    index = [i for f in hand_reach.hand.fingers for i in f.joint_index]
    if len(hand_reach.hand.fingers) != 3 or len(set(index)) != len(index):
        raise ValueError("a hand searched over must have three fingers that share no joint")
    return hand_reach


def reach(hand_reach: HandReach, points, normals) -> Reached:
    """Put the hand on each candidate (module docstring): ``(N, 3, 3)`` contacts and unit inward normals.

    Examples
    --------
    Three one-joint fingers, each a prismatic joint along z through its contact; each reaches
    only its own contact's vertical line, so the second candidate's assignment swaps fingers 1 and 2:

    >>> from grasptwist.hand import Finger, Hand, Joint
    >>> base = np.array([[1.0, 0, 0], [0, 1.0, 0], [-1.0, 0, 0]])
    >>> def finger(i):
    ...     tip = np.eye(4); tip[:3, 3] = base[i]
    ...     j = (Joint(f"z{i}", "prismatic", None, -2.0, 2.0, None),)
    ...     return Finger(str(i), None, j, np.array([[0, 0, 0, 0, 0, 1.0]]), base[i : i + 1] - [0, 0, 1], tip, 1.0, (i,))
    >>> hand = Hand(tuple(finger(i) for i in range(3)), ("z0", "z1", "z2"), None, None)
    >>> far = lambda q: (q, -q, np.full(q.shape[:-1], 10.0))  # nothing near: every sphere is clear
    >>> r = reach(HandReach(hand, np.array([f.tip_pose for f in hand.fingers]), np.zeros(3), far, 1e-6),
    ...           [base + [0, 0, 0.5], base[[0, 2, 1]] + [0, 0, -1.0]], -base[None].repeat(2, 0))
    >>> r.failed.tolist(), r.order.tolist(), r.positions.round(12).tolist()
    ([-1, -1], [[0, 1, 2], [0, 2, 1]], [[0.5, 0.5, 0.5], [-1.0, -1.0, -1.0]])
    """
    hr = hand_reach
    p, n = np.asarray(points, float), np.asarray(normals, float)
    rows = len(p)
    fingers = hr.hand.fingers
    radii = np.asarray(hr.radii, float)
    # pair (row, shift s, finger f): finger f on contact (f + s) mod 3, its sphere's centre one radius out
    contact = (np.arange(3)[None, :] + np.arange(3)[:, None]) % 3  # (s, f)
    centre = p[:, contact] - radii[None, None, :, None] * n[:, contact]
    clear = hr.project(centre)[2] >= radii - hr.tolerance  # (N, 3, 3)
    if has_obstacles(hr.environment):  # and clear of the table and the boxes
        clear &= sphere_distance(centre, radii, hr.environment)[0] >= hr.clearance
    # each pair's distance from reaching: inf off the surface, how far out of a revolute chain's
    # reach (no solve needed), 0 until solved (``unsolved``)
    error = np.full((rows, 3, 3), np.inf)
    unsolved = np.zeros((rows, 3, 3), bool)
    for f, finger in enumerate(fingers):
        revolute = all(j.type == "revolute" for j in finger.joints)
        gap = np.linalg.norm(centre[:, :, f] - finger.points[0], axis=-1) - finger.length if revolute else -1.0
        gap = np.broadcast_to(gap, (rows, 3))
        error[:, :, f] = np.where(clear[:, :, f], np.maximum(gap, 0.0), np.inf)
        unsolved[:, :, f] = clear[:, :, f] & (gap <= 0)
    q = np.full((rows, 3, 3, max(len(f.joints) for f in fingers)), np.nan)
    pick = (slice(None), _SHIFTS[:, :], np.arange(3)[None, :])  # (N, 6 assignments, 3 fingers)
    touches = clear[pick].all(axis=-1)
    # the assignments tried nearest first (the fingers' first joints to their targets, in all): a finger
    # that reaches around the object to a far contact is the one whose links go through it
    base = np.array([f.points[0] for f in fingers])  # (3, 3)
    spread = np.linalg.norm(centre - base, axis=-1)[pick].sum(axis=-1)  # (N, 6)
    ranked = np.argsort(np.where((error[pick] == 0).all(axis=-1), spread, np.inf), axis=1, kind="stable")
    # the nearest assignment's pairs solved first: most candidates are held by it, and never need the rest
    first = np.zeros((rows, 3, 3), bool)
    first[np.arange(rows)[:, None], _SHIFTS[ranked[:, 0]], np.arange(3)] = True
    _solve(hr, centre, unsolved & first, q, error)
    failed = np.full(rows, HAND_CONSTRAINTS.index("fingertips"), np.int8)
    failed[touches.any(axis=1)] = HAND_CONSTRAINTS.index("reach")
    order = np.tile(np.arange(3), (rows, 1))
    positions = np.full((rows, len(hr.hand.joint_names)), np.nan)
    depth = np.full(rows, np.inf)
    _assign(hr, q, error, ranked[:, :1], failed, order, positions, depth)
    rest = (failed != -1) & touches.any(axis=1)  # then every pair of the rows still without one
    _solve(hr, centre, unsolved & ~first & rest[:, None, None], q, error)
    _assign(hr, q, error, np.where(rest[:, None], ranked[:, 1:], -1), failed, order, positions, depth)
    worst = error[pick].max(axis=-1)  # (N, 6): 0 where every finger reaches
    miss = np.where(touches.any(axis=1), worst.min(axis=1, initial=np.inf), np.nan)
    miss = np.where(failed == HAND_CONSTRAINTS.index("collision"), depth, miss)
    return Reached(failed, order, positions, np.where(failed == -1, np.nan, miss))


def _solve(hand_reach, centre, todo, q, error):
    """The fingers' inverse kinematics on the ``(N, 3, 3)`` pairs ``todo``, in one batch
    (:func:`~grasptwist.engine.ik.fingers_ik`), into ``q`` (joint positions) and ``error`` (0 where
    the finger reaches, else its tip's least distance)."""
    row, shift, finger = np.nonzero(todo)
    if row.size:
        got, err, status = fingers_ik(
            hand_reach.hand.fingers, hand_reach.tips, finger, centre[row, shift, finger], seeds=IK_RESTARTS
        )
        q[row, shift, finger, : got.shape[1]] = got
        error[row, shift, finger] = np.where(status == Status.OK, 0.0, err)


def _assign(hand_reach, q, error, ranked, failed, order, positions, depth):
    """Of each row's assignments ``ranked`` (``(N, R)``, nearest first, -1: none), the first whose
    fingers reach and whose hand is clear (:func:`violations`, one batch for them all) is kept: its
    ``order`` and joint ``positions``, ``failed`` -1; a row whose reached ones all collide gets
    ``failed`` ``collision`` and in ``depth`` the least of their violations."""
    hr = hand_reach
    row, rank = np.nonzero(ranked >= 0)
    k = ranked[row, rank]
    reached = (error[row[:, None], _SHIFTS[k], np.arange(3)] == 0).all(axis=1) & (failed[row] != -1)
    row, rank, k = row[reached], rank[reached], k[reached]
    if not row.size:
        return
    trial = np.empty((row.size, len(hr.hand.joint_names)))
    for f, finger in enumerate(hr.hand.fingers):
        trial[:, list(finger.joint_index)] = q[row, _SHIFTS[k, f], f, : len(finger.joints)]
    deep = violations(hr, trial)
    np.minimum.at(depth, row, deep)
    failed[row] = HAND_CONSTRAINTS.index("collision")
    ok = np.flatnonzero(deep <= 0)
    # each row's first clear assignment: ``ok`` is in row-major order, nearest first within a row
    ok = ok[np.unique(row[ok], return_index=True)[1]]
    won = row[ok]
    failed[won], order[won], positions[won] = -1, _ORDERS[k[ok]], trial[ok]


def violations(hand_reach: HandReach, positions):
    r"""How far the hand at joint positions breaks its collision tests (> 0: broken, module docstring 3.).

    .. math::

        v = \max\bigl(d_\text{object} - \text{tol},\; d_\text{fingers} - \text{tol},\;
            c_\min - \phi_E\bigr)

    with :math:`d_\text{object}` the deepest link in the object (``collide``), :math:`d_\text{fingers}`
    the deepest overlap of two fingers' parts and :math:`\phi_E` the least distance of any part from
    the environment, tested in that order: a row that breaks one test is not put to the next, and
    gets the first one's (a lower bound of :math:`v`, > 0 all the same).  ``(N, n_joints)`` -> ``(N,)``.
    """
    hr = hand_reach
    q = np.asarray(positions, float)
    out = np.full(len(q), -np.inf)
    if hr.collide is not None and len(q):
        out = np.asarray(hr.collide(q), float) - hr.tolerance
    live = np.flatnonzero(out <= 0)
    if live.size:
        hulls, poses, centers = _parts_at(hr, q[live])
        overlap = finger_overlaps(hulls, poses, centers, hr.radii).reshape(live.size, -1)
        out[live] = np.maximum(out[live], overlap.max(axis=1, initial=0.0) - hr.tolerance)
        clear = out[live] <= 0
        if has_obstacles(hr.environment) and clear.any():
            k = live[clear]
            distance = _distance(hr, hulls, poses[clear], centers[clear])
            out[k] = np.maximum(out[k], hr.clearance - distance)
    return out


def hand_clearance(hand_reach: HandReach, positions):
    """The least signed distance of any part of the hand (links, fingertip spheres) from its environment
    at joint positions, :func:`~grasptwist.engine.environment.parts_distance`: ``(N, n_joints)`` -> ``(N,)``
    (``inf`` without one)."""
    q = np.asarray(positions, float)
    if not has_obstacles(hand_reach.environment):
        return np.full(len(q), np.inf)
    return _distance(hand_reach, *_parts_at(hand_reach, q))


def _distance(hand_reach, hulls, poses, centers):
    """The least distance of any part from the environment, the parts placed (:func:`_parts_at`)."""
    links = len(hulls.links)
    env = hand_reach.environment
    return parts_distance(hulls.parts, links, poses, centers, hand_reach.radii, env)[0].min(axis=1)


def _parts_at(hand_reach, q):
    """The links' hulls, their poses and the fingertip spheres' centres at joint positions ``q``."""
    hulls = link_hulls(()) if hand_reach.hulls is None else hand_reach.hulls
    return hulls, link_poses(hand_reach.hand, hulls.links, q), tip_centers_at(hand_reach.hand, hand_reach.tips, q)


def tip_errors(hand_reach: HandReach, points, normals, positions):
    """Each finger's distance from its tip point, by forward kinematics at ``positions``, to ``p - r n``.

    ``(K, 3, 3)`` contacts (row ``f`` finger ``f``'s), normals, ``(K, n_joints)`` -> ``(K, 3)``: the
    check, independent of the inverse kinematics, of the grasps a search returns.
    """
    p, n = np.asarray(points, float), np.asarray(normals, float)
    centre = p - np.asarray(hand_reach.radii, float)[:, None] * n
    out = np.empty(p.shape[:-1])
    for f, finger in enumerate(hand_reach.hand.fingers):
        q = np.asarray(positions, float)[:, list(finger.joint_index)]
        tip = forward_kinematics(finger.screws, finger.points, hand_reach.tips[f], q).tip[..., :3, 3]
        out[:, f] = np.linalg.norm(tip - centre[:, f], axis=-1)
    return out


def reach_tolerance(hand_reach: HandReach):
    """How far each finger's tip point may be from its target: :data:`~grasptwist.engine.ik.IK_TOL`
    times the finger's length, ``(3,)`` (the inverse kinematics' own test).
    """
    return IK_TOL * np.array([f.length for f in hand_reach.hand.fingers])
