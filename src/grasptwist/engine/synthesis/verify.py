"""Verification: each grasp a search selects solved again, one row at a time, by the exact grip.

A grasp is returned only when the certificate of its grip proves the least total normal force
optimal (:func:`verified`: ``dual`` with a zero ``gap``, ``n_i - G_i^T dual`` in every dual cone),
and with a hand when the hand placed on it by forward kinematics touches every contact within the
inverse kinematics' tolerance, within its joint limits and clear of the object, the other fingers
and the environment (:func:`held`).  Grasps whose turn comes after the budget's deadline are
counted, not verified (:func:`verify`).
"""

from __future__ import annotations

import numpy as np

from ..degeneracy import DEGENERACY_TOL
from ..fingertips import tip_centers
from ..forces.closure import force_closure
from ..forces.grip import Grip, grip
from ..ik import joint_limits
from .reach import reach_tolerance, tip_errors, violations
from .scores import conditionings

__all__ = ["GAP_TOL", "verified", "verify", "held"]

#: A verified grip's duality gap must be within this of its total (relative).
GAP_TOL = 1e-6


def verified(points, normals, wrench, friction, safety, tol=DEGENERACY_TOL, torsion=None) -> Grip | None:
    r"""The exact grip of one grasp and wrench when its certificate proves it optimal, else None.

    One row through :func:`~grasptwist.engine.forces.grip.grip`; its ``dual`` must close the gap
    (``|total - w . dual| <= GAP_TOL max(total, 1)``) and be dual feasible:
    ``n_i - G_i^T dual`` (``G_i^T dual = dual_F + dual_M x p_i``) in each dual cone
    ``(mu / s) |z_t| <= z_n``, to :data:`GAP_TOL`; with ``mu = inf`` (the half-space
    ``f . n >= 0``, no limit) the dual cone is the ray along ``n``: ``|z_t| = 0 <= z_n``.  With ``torsion``
    (soft contacts' radius ``e``) the grip is over the soft cones and ``|z_t|`` is ``|(z_t, e z_tau)|``,
    ``z_tau = -n_i . dual_M``.

    >>> p = np.array([[1.0, 0, 0], [-0.5, 0.75**0.5, -0.2], [-0.5, -(0.75**0.5), -0.2]])
    >>> g = verified(p, -p / np.linalg.norm(p, axis=1, keepdims=True), [0, 0, 1.0, 0, 0, 0], 0.5, 1.0)
    >>> g is not None and bool(g.ok)
    True
    >>> g = verified(p, -p / np.linalg.norm(p, axis=1, keepdims=True), [0, 0, 1.0, 0, 0, 0], np.inf, 1.0)
    >>> g is not None and bool(g.total_normal_force < 1e-6)  # tangential forces alone hold it
    True
    """
    g = grip(points, normals, wrench, friction, safety=safety, torsion=torsion, tol=tol)
    if not g.ok:
        return None
    total = float(g.total_normal_force)
    if not abs(float(g.gap)) <= GAP_TOL * max(total, 1.0):
        return None
    n = np.asarray(normals, float)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    z = n - (g.dual[:3] + np.cross(g.dual[3:], np.asarray(points, float)))
    zn = np.sum(z * n, axis=-1)
    zt = np.linalg.norm(z - zn[:, None] * n, axis=-1)
    if torsion is not None:  # the soft cones' dual: the torsion's multiplier beside the tangential ones
        zt = np.hypot(zt, torsion * np.sum(n * g.dual[3:], axis=-1))
    limit = friction / safety
    # no limit: (mu / s) |z_t| is inf * 0 on the ray, so ask for the ray itself
    inside = (zt <= GAP_TOL) & (zn >= -GAP_TOL) if np.isinf(limit) else limit * zt - zn <= GAP_TOL
    return g if inside.all() else None


def verify(
    surface,
    points,
    normals,
    w,
    mu,
    safety,
    wrist,
    methods,
    quality,
    tol,
    hand=None,
    positions=None,
    budget=None,
    torsion=None,
) -> dict:
    """The returned grasps' fields of :class:`Synthesis`, each grasp verified (the others dropped): the
    exact grip, and with a hand its tips by forward kinematics, its limits and its links clear; those
    whose turn comes after the ``budget``'s deadline (:meth:`~.budget.Spending.late`) are not verified,
    only counted.  Epsilon (``quality``: a convex hull a grasp, milliseconds each) is computed at each
    grasp's turn, within the deadline."""
    grips, keep, epsilon, unverified = [], [], [], 0
    for i in range(len(points)):
        if budget is not None and budget.late():
            unverified = len(points) - i
            break
        found = tuple(verified(points[i], normals[i], wrench, mu, safety, tol, torsion) for wrench in w)
        if all(g is not None for g in found):
            grips.append(found)
            keep.append(i)
            if quality:
                c = force_closure(points[i], normals[i], mu / safety, torsion=torsion, quality=True, tol=tol)
                epsilon.append(float(c.epsilon))
    hand_fields = {}
    if hand is not None:
        error = tip_errors(hand, points[keep], normals[keep], positions[keep])
        good = held(hand, error, positions[keep])
        grips, keep = [g for g, k in zip(grips, good) if k], [i for i, k in zip(keep, good) if k]
        epsilon = [e for e, k in zip(epsilon, good) if k]
        hand_fields = {
            "joint_positions": positions[keep],
            "reach_error": error[good],
            "tip_center": tip_centers(points[keep], normals[keep], hand.radii),
        }
    p, n = points[keep], normals[keep]
    closure = force_closure(p, n, mu / safety, torsion=torsion, tol=tol) if len(p) else None
    return {
        "points": p,
        "normals": n,
        "surface_distance": surface.project(p)[2] if len(p) else np.empty((0, 3)),
        "total_normal_force": np.array([[float(g.total_normal_force) for g in row] for row in grips]).reshape(
            len(p), len(w)
        ),
        "closure_friction": closure.closure_friction if closure else np.empty(0),
        "epsilon": np.array(epsilon) if quality else None,
        "conditioning": conditionings(p, n, wrist, methods, tol) if len(p) else np.empty((0, 2)),
        "grips": tuple(grips),
        "unverified": unverified,
        **hand_fields,
    }


def held(hand, error, positions):
    """Which placed hands are verified: every tip on its target (:func:`~.reach.reach_tolerance`), every
    joint within its limits, no collision (:func:`~.reach.violations`: ``(K, 3)``, ``(K, n_joints)`` -> ``(K,)``)."""
    good = (error <= reach_tolerance(hand)).all(axis=1)
    for finger in hand.hand.fingers:
        lower, upper = joint_limits(finger)
        q = positions[:, list(finger.joint_index)]
        good &= ((q >= lower) & (q <= upper)).all(axis=1)
    return good & (violations(hand, positions) <= 0)
