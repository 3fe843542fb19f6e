r"""Fingertips that roll: the joint positions under which each fingertip sphere rolls on the moving
object without slipping, the paper's resolved rates taken at the contact where the sphere touches.

The paper's point contact with friction is the no-slip condition at the contact: the finger's
point at the contact moves with the object's point there, ``J_f(q) qdot_f = T(p_f)``
(:func:`~grasptwist.engine.kinematics.joint_rates`, the resolved finger twist's joint rates).  A
fingertip sphere of radius ``r`` about the point ``c_f(q)`` of its tip link touches the object at
``p_f``, the surface point nearest ``c_f`` (``c = p - r n``, ``n`` the inward normal there).
Integrating

.. math::

    \dot q_f = J_f(q, p_f)^+ \bigl(T_s(t)(p_f) + k\,(d_f - r_f)\,n_f\bigr),

with ``p_f``, ``n_f`` and the distance ``d_f = |p_f - c_f|`` taken afresh at each step, lets the
contact move over both surfaces as the sphere rolls (Montana, "The kinematics of contact and
grasp", 1988); the feedback (``k = 1 / (2 h)`` for a step ``h``) keeps the sphere on the surface
against the integration's drift.

:func:`grasptwist.engine.hands.track` (``follow``) instead holds the contact fixed on the object,
so the sphere's surface slides over it at ``r omega_rel x n`` (``omega_rel`` the object's angular
velocity less the tip link's): executed, where friction holds, the sticking tips roll the object
back (``docs/guide/simulation.md``, "Paths": the TriFinger's 0.5 rad spin ends 9 degrees behind
its plan that way, 0.5 degree this way).  Without a hand each fingertip is a sphere on three slides
(it never turns): its centre moves with the object's point at the contact.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .fingertips import tip_centers
from .kinematics import forward_kinematics, joint_rates
from .objects.geometry import moved, project_to_surface
from .path import integrate
from .se3 import inverse, transform

__all__ = ["Rolling", "roll"]


class Rolling(NamedTuple):
    """Fingertips rolling along a path (:func:`roll`), at the given times ``(T,)``.

    Attributes
    ----------
    positions, rates : (T, n_joints)
        The joint positions and the no-slip rates there (without a hand: the three slides of each
        fingertip, ``(T, 9)``, their displacement from the start).
    centers : (T, 3, 3)
        Each sphere's centre.
    points, normals : (T, 3, 3)
        Each contact (the object's surface point nearest the centre) and its inward normal.
    """

    positions: np.ndarray
    rates: np.ndarray
    centers: np.ndarray
    points: np.ndarray
    normals: np.ndarray


def _fingers(hand, q, local, start):
    """Each sphere's centre ``(3, 3)`` at ``q``, and each finger's joint screws (None without a hand)."""
    if hand is None:
        return start + q.reshape(3, 3), None
    states = _states(hand, q)
    centres = np.stack([transform(s.tip[:3, :3], s.tip[:3, 3], c) for s, c in zip(states, local)])
    return centres, [s.screws for s in states]


def _states(hand, q):
    """Each finger's joint screws and its product of exponentials ``g_f(q)`` (a frame its tip link carries)."""
    return [forward_kinematics(f.screws, f.points, np.eye(4), q[list(f.joint_index)]) for f in hand.fingers]


def roll(hand, positions, obj, points, normals, radii, segments, times) -> Rolling:
    """The fingertips rolling without slip on ``obj`` moved along ``segments`` (module docstring).

    Integrated by the classical fourth-order Runge-Kutta method, one step per interval of ``times``.

    Parameters
    ----------
    hand : Hand or None
        None: three spheres on slides.
    positions : (n_joints,) array or None
        The joint positions at ``t = 0`` (ignored without a hand).
    obj : GraspObject
        The object at ``t = 0``.
    points, normals : (3, 3) arrays
        The contacts at ``t = 0`` and their inward normals.
    radii : (3,) array
        The spheres' radii.
    segments : sequence of Segment
    times : (T,) array
        Increasing, from 0.

    Returns
    -------
    Rolling

    Examples
    --------
    A ball of radius 1 slid along x at speed 1 for 1 s between three spheres on slides: they
    move with it.

    >>> from grasptwist.objects import GraspObject, Shape
    >>> from grasptwist.path import Segment
    >>> ball = GraspObject(Shape("sphere", np.array([1.0])), np.eye(4))
    >>> p = np.array([[1.0, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])
    >>> r = roll(None, None, ball, p, -p, np.full(3, 0.1), [Segment(1.0, twist=[0, 0, 0, 1, 0, 0])], [0.0, 0.5, 1.0])
    >>> r.positions[-1].round(9).reshape(3, 3)[:, 0].tolist()
    [1.0, 1.0, 1.0]
    """
    times = np.asarray(times, dtype=float)
    radii = np.asarray(radii, dtype=float)
    start = tip_centers(np.asarray(points, float), np.asarray(normals, float), radii)
    q = np.zeros(9) if hand is None else np.asarray(positions, dtype=float).copy()
    local = None
    if hand is not None:  # each centre in its tip link's frame
        local = [transform(*inverse(s.tip[:3, :3], s.tip[:3, 3]), c) for s, c in zip(_states(hand, q), start)]

    def state(t, q):
        pose = integrate(segments, t)
        place = np.eye(4)
        place[:3, :3], place[:3, 3] = pose.rotation, pose.position
        centres, screws = _fingers(hand, q, local, start)
        surface = project_to_surface(moved(obj, place), centres)
        return pose.twist, centres, screws, surface

    def rates(t, q, gain):
        twist, centres, screws, s = state(t, q)
        velocity = np.cross(twist[:3], s.points) + twist[3:] + gain * (s.distance - radii)[:, None] * s.normals
        if hand is None:  # a sphere on slides never turns: its centre moves with its contact point
            return velocity.ravel(), (centres, s)
        out = np.zeros_like(q)
        for f, finger in enumerate(hand.fingers):
            out[list(finger.joint_index)] = joint_rates(screws[f], s.points[f], velocity[f]).rates
        return out, (centres, s)

    rows = {"positions": [], "rates": [], "centers": [], "points": [], "normals": []}
    for k, t in enumerate(times):
        if k:
            h = t - times[k - 1]
            gain, t0 = 0.5 / h, times[k - 1]
            k1 = rates(t0, q, gain)[0]
            k2 = rates(t0 + h / 2, q + h / 2 * k1, gain)[0]
            k3 = rates(t0 + h / 2, q + h / 2 * k2, gain)[0]
            k4 = rates(t, q + h * k3, gain)[0]
            q = q + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        qdot, (centres, s) = rates(t, q, 0.0)
        for name, value in zip(rows, (q.copy(), qdot, centres, s.points, s.normals)):
            rows[name].append(value)
    return Rolling(*(np.array(v) for v in rows.values()))
