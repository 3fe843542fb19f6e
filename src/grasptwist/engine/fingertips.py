"""Fingertips with a radius: where the tip's sphere sits at its contact, and where it touches.

A fingertip is a sphere of radius ``r`` about its tip link's origin (``r = 0``:
a point tip).  At a contact ``p`` with unit normal ``n`` pointing into the
object, the sphere touches the object's surface at ``p`` when its centre is

.. math::

    c = p - r\\,n,

so inverse kinematics puts the tip link's origin on ``c``
(:func:`tip_centers`), while joint rates stay those of the finger's point at
the contact ``p`` (:mod:`.kinematics`).

Along a path the contact is fixed on the object (the paper's point contact
with friction: the finger pushes on one point of the object), so ``p(t)`` and
``n(t)`` are carried by the object's pose and the centre tracks
``c(t) = p(t) - r n(t)``: a point fixed on the object, too.  With the tip link
at ``(R_t, o)`` (forward kinematics), the sphere's gap to the tangent plane at
``p(t)`` and the point of the sphere that touches it are (:func:`tip_contacts`)

.. math::

    g = (p - o) \\cdot n - r, \\qquad u = R_t^\\top n,

``g > 0`` a gap, ``g < 0`` a penetration, ``u`` a unit vector in the tip link's
frame (the sphere touches at ``o + r R_t u``).  As the object turns by ``R_o``
and the tip link by ``R_t``, ``u`` turns by their relative rotation
``R_t^\\top R_o`` (docs/guide/paths.md, "Rolling fingertips").
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .screws import dot, unit

__all__ = [
    "TipContacts",
    "tip_radii",
    "tip_centers",
    "tip_contacts",
    "sphere_radius",
    "SPHERE_TOL",
    "SPHERE_VERTICES",
    "SPHERE_SAG",
]

#: Two of a mesh's vertices lie on one sphere about a point when their distances from it agree
#: to this, relative (a float32 STL's round-off is some 1e-7).
SPHERE_TOL = 1e-6

#: A mesh is a sphere (or a cap of one) about a point when at least this many of its vertices lie
#: on the sphere through the most of them, at as many distinct latitudes about each of their
#: principal axes (:func:`sphere_radius`).
SPHERE_VERTICES = 16

#: ... and none lies farther inside that sphere than this fraction of its radius.
SPHERE_SAG = 0.05


def tip_radii(hand):
    """Each finger's fingertip radius, ``(3,)`` (0: a point tip).

    Examples
    --------
    >>> from grasptwist.hand import Finger, Hand
    >>> f = Finger("a", None, (), None, None, None, 1.0, (), tip_radius=0.01)
    >>> tip_radii(Hand((f, f, f), (), None, None)).tolist()
    [0.01, 0.01, 0.01]
    """
    return np.array([f.tip_radius for f in hand.fingers], dtype=float)


def tip_centers(points, normals, radii):
    """The fingertip spheres' centres touching the contacts: ``c = p - r n``.

    .. math:: c_f = p_f - r_f \\, \\hat n_f

    Parameters
    ----------
    points : (..., 3, 3) array
        The contacts, row ``f`` touched by finger ``f``.
    normals : (..., 3, 3) array
        Their normals, into the object (any non-zero length).
    radii : (3,) array
        Each finger's tip radius.

    Returns
    -------
    (..., 3, 3) array

    Examples
    --------
    >>> tip_centers([[0.0, 0, 1]] * 3, [[0, 0, 2.0]] * 3, [0.0, 0.5, 1.0])[:, 2].tolist()
    [1.0, 0.5, 0.0]
    """
    points = np.asarray(points, dtype=float)
    radii = np.asarray(radii, dtype=float)
    if not radii.any():  # point tips: the contacts themselves, whatever the normals
        return points
    return points - radii[:, None] * unit(np.asarray(normals, dtype=float))


class TipContacts(NamedTuple):
    """Where each fingertip sphere is against its contact's tangent plane (:func:`tip_contacts`)."""

    #: ``(..., 3)`` signed distance from the sphere to the tangent plane: > 0 a gap, < 0 a penetration.
    gap: np.ndarray
    #: ``(..., 3, 3)`` the point of the sphere facing the object, a unit vector in the tip link's frame.
    contact: np.ndarray


def tip_contacts(tip_poses, points, normals, radii) -> TipContacts:
    """Each fingertip's gap to its contact's tangent plane, and where on the tip it touches.

    .. math::

        g_f = (p_f - o_f) \\cdot \\hat n_f - r_f, \\qquad u_f = R_f^\\top \\hat n_f,

    ``(R_f, o_f)`` the tip link's pose, ``n_f`` the contact's normal into the object.

    Parameters
    ----------
    tip_poses : (..., 3, 4, 4) array
        Each finger's tip link pose (for a finger given inline, the frame
        its tip point is carried by: :func:`~grasptwist.hand.home_tips`).
    points, normals : (..., 3, 3) arrays
    radii : (3,) array

    Returns
    -------
    TipContacts

    Examples
    --------
    A tip of radius 1 at height 1 above a floor (normal down, into it),
    turned a quarter turn about x (its ``-y`` now points down): it touches the floor there:

    >>> pose = np.eye(4); pose[:3, :3] = [[1, 0, 0], [0, 0, -1], [0, 1, 0]]; pose[2, 3] = 1.0
    >>> g = tip_contacts([pose] * 3, [[0.0, 0, 0]] * 3, [[0, 0, -1.0]] * 3, [1.0, 1.0, 0.5])
    >>> g.gap.tolist(), (g.contact[0] + 0.0).tolist()
    ([0.0, 0.0, 0.5], [0.0, -1.0, 0.0])
    """
    poses = np.asarray(tip_poses, dtype=float)
    n = unit(np.asarray(normals, dtype=float))
    gap = dot(np.asarray(points, dtype=float) - poses[..., :3, 3], n) - np.asarray(radii, dtype=float)
    contact = (np.swapaxes(poses[..., :3, :3], -1, -2) @ n[..., None])[..., 0]
    return TipContacts(gap, contact)


def sphere_radius(vertices):
    """The radius of a mesh that is a sphere, or a cap of one, about the origin; None if it is not.

    The sphere is the one through the most vertices (within ``SPHERE_TOL``
    (1e-6) of its radius ``r``, relative); at least ``SPHERE_VERTICES`` (16)
    must lie on it, spread over at least as many latitudes (a hundredth of
    ``r`` apart) along each of their principal axes: a tessellated sphere or
    hemisphere, not a box's corners or the two rims of a cylinder, which are
    equidistant too.  No vertex may lie more than ``SPHERE_SAG`` (5 %) inside
    it (a cap closed by a flat face has its rim on chords, a little inside).

    Parameters
    ----------
    vertices : (V, 3) array
        In the frame whose origin is the sphere's centre (a tip link's).

    Returns
    -------
    float or None

    Examples
    --------
    >>> u = np.random.default_rng(0).normal(size=(200, 3)); u[:, 2] = -np.abs(u[:, 2])
    >>> round(sphere_radius(0.01 * u / np.linalg.norm(u, axis=1, keepdims=True)), 12)  # a hemisphere
    0.01
    >>> ring = np.stack([np.cos(np.arange(64)), np.sin(np.arange(64)), np.repeat([-1.0, 1.0], 32)], 1)
    >>> sphere_radius(ring) is None  # the rims of a cylinder
    True
    """
    v = np.asarray(vertices, dtype=float).reshape(-1, 3)
    d = np.linalg.norm(v, axis=-1)
    if not v.size or not np.isfinite(d).all() or d.min() <= 0:
        return None
    ordered = np.sort(d)
    count = np.searchsorted(ordered, ordered * (1 + SPHERE_TOL), side="right") - np.arange(len(d))
    r = float(ordered[np.argmax(count)])  # the distance most vertices share (the nearest such)
    on = v[np.abs(d - r) <= SPHERE_TOL * r] / r
    if len(on) < SPHERE_VERTICES or d.min() < (1 - SPHERE_SAG) * r:
        return None
    axes = np.linalg.eigh(np.cov(on.T))[1]
    latitudes = np.round(on @ axes, 2)
    spread = min(len(np.unique(latitudes[:, k])) for k in range(3))
    return r if spread >= SPHERE_VERTICES else None
