"""Judgements on a resolved twist: which fingers each component moves, and
whether the twist is a rotation about the wrist; and on a grasp: which of
its normals look outward; and on a path: whether a rotation looks given in degrees.

These are engine outputs like the amplitudes: pure functions on result
arrays, batched over any leading shape, whose answers the records carry
(``moves``, ``about_wrist``) and the tables only print.

Which fingers a basis screw moves is fixed by the paper's construction:
``Sigma_i`` is the line through ``p_j`` and ``p_k``, so it moves finger
``i`` alone (Proposition 1); ``Psi_i`` (the line from the wrist through
``p_i``) and ``Theta_i`` (eq. 22, a line through ``p_i``) keep finger ``i``
still and move the other two.  A *component* ``a_c S_c`` moves those
fingers when its amplitude ``a_c`` is more than round-off.

Round-off is judged relative to like quantities of the same row, so the
answers do not depend on the grasp's scale or position: an amplitude
against the largest amplitude of its decomposition (amplitudes of unit
lines all have the dimension of an angular rate), a normal velocity
against the largest normal velocity, both with the engine's
:data:`~grasptwist.engine.degeneracy.IN_PLANE_TOL`.  Rows whose method
failed (NaN amplitudes) move nothing.
"""

from __future__ import annotations

import numpy as np

from .degeneracy import IN_PLANE_TOL
from .screws import dot

__all__ = [
    "ALONE",
    "ALL_BUT",
    "active",
    "off_tangent_moves",
    "tangent_moves",
    "about_wrist",
    "outward_contacts",
    "normal_angles",
    "rotation_over_pi",
]

#: ``ALONE[i, f]``: the basis screw ``Sigma_i`` moves finger ``f`` (``f == i`` only).
ALONE = np.eye(3, dtype=bool)
ALONE.flags.writeable = False

#: ``ALL_BUT[i, f]``: ``Psi_i`` and ``Theta_i`` move finger ``f`` (every ``f != i``).
ALL_BUT = ~ALONE
ALL_BUT.flags.writeable = False


def active(values, tol=IN_PLANE_TOL):
    """Which values are more than round-off next to the largest of their row.

    .. math::

        |a_c| > \\mathrm{tol} \\, \\max_{c'} |a_{c'}|

    Parameters
    ----------
    values : (..., k) array
        Like quantities of one row (amplitudes, or normal velocities).
    tol : float
        Relative tolerance.

    Returns
    -------
    (..., k) bool
        False throughout a row of zeros or of NaN.

    >>> active([1.0, 1e-12, 0.0, -0.5]).tolist()
    [True, False, False, True]
    """
    a = np.abs(np.asarray(values, dtype=float))
    with np.errstate(invalid="ignore"):
        return a > tol * np.max(a, axis=-1, keepdims=True)


def _moves(first, second, first_pattern, second_pattern):
    """``(..., 6, 3)`` from the activity of two groups of three components."""
    return np.concatenate(
        (first[..., :, None] & first_pattern, second[..., :, None] & second_pattern),
        axis=-2,
    )


def off_tangent_moves(x, y, tol=IN_PLANE_TOL):
    """Which fingers each off-tangent component moves.

    Components in basis order: ``x_1 Sigma_1 .. x_3 Sigma_3`` (``Sigma_i``
    moves finger ``i`` alone), then ``y_1 Psi_1 .. y_3 Psi_3`` (``Psi_i``
    keeps finger ``i`` still); a component is active when its amplitude is
    (see :func:`active`, over all six amplitudes of eq. 14).

    Parameters
    ----------
    x, y : (..., 3) arrays
        The amplitudes of :func:`~grasptwist.engine.decompose.decompose_off_tangent`.
    tol : float

    Returns
    -------
    (..., 6, 3) bool
        ``[..., c, f]``: component ``c`` moves finger ``f``.

    Examples
    --------
    A spin about the axis through the wrist (paper Example 1b): only the
    ``Psi`` part, each ``Psi_i`` moving the two other fingers:

    >>> m = off_tangent_moves([0.0, 0.0, 0.0], [-0.4714, -0.4714, -0.4714])
    >>> [np.flatnonzero(c).tolist() for c in m]
    [[], [], [], [1, 2], [0, 2], [0, 1]]
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    on = active(np.concatenate((x, y), axis=-1), tol)
    return _moves(on[..., :3], on[..., 3:], ALONE, ALL_BUT)


def tangent_moves(alpha, beta, normal_velocity, in_tangent_planes, tol=IN_PLANE_TOL):
    """Which fingers each tangent-method component moves.

    Components in basis order: ``alpha_1 Theta_1 .. alpha_3 Theta_3``
    (``Theta_i`` keeps finger ``i`` still, the others sliding), active when
    the amplitude is among all six; then the off-plane rest ``beta_1 Sigma_1
    .. beta_3 Sigma_3`` (finger ``i`` alone).  ``beta_i`` is set by finger
    ``i``'s normal velocity (``beta_i Sigma_i(p_i) . n_i = T(p_i) . n_i``),
    so it is judged by it: active when the twist is not in the tangent
    planes and ``|T(p_i) . n_i|`` is not round-off next to the largest
    normal velocity.  Hence no ``Sigma`` component is active exactly when
    ``in_tangent_planes`` holds.

    Parameters
    ----------
    alpha, beta, normal_velocity : (..., 3) arrays
    in_tangent_planes : (...) bool array
        As returned by :func:`~grasptwist.engine.decompose.decompose_tangent`.
    tol : float

    Returns
    -------
    (..., 6, 3) bool
        ``[..., c, f]``: component ``c`` moves finger ``f``.

    Examples
    --------
    Paper Example 2 (``alpha_i = 0.5774``, in the tangent planes), then a
    twist that lifts finger 3 off its plane:

    >>> m = tangent_moves([0.5774] * 3, [0.0] * 3, [0.0] * 3, True)
    >>> [np.flatnonzero(c).tolist() for c in m]
    [[1, 2], [0, 2], [0, 1], [], [], []]
    >>> m = tangent_moves([0.0, 0.2, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.3], False)
    >>> [np.flatnonzero(c).tolist() for c in m]
    [[], [0, 2], [], [], [], [2]]
    """
    alpha, beta = np.asarray(alpha, dtype=float), np.asarray(beta, dtype=float)
    theta = active(np.concatenate((alpha, beta), axis=-1), tol)[..., :3]
    off_plane = active(normal_velocity, tol) & ~np.asarray(in_tangent_planes, dtype=bool)[..., None]
    return _moves(theta, off_plane, ALL_BUT, ALONE)


def about_wrist(x, y, tol=IN_PLANE_TOL):
    """Whether the twist is a rotation about the wrist: a ``Psi`` part and no ``Sigma`` part.

    Every ``Psi_i`` passes through the wrist ``c``, so a twist made of them
    alone is a rotation about an axis through ``c`` (``T(c) = 0``), which
    the wrist alone could make.  The zero twist is not one.

    Parameters
    ----------
    x, y : (..., 3) arrays
        The off-tangent amplitudes (eq. 14).
    tol : float

    Returns
    -------
    (...) bool

    >>> about_wrist([0.0, 0.0, 0.0], [-0.4714, -0.4714, -0.4714]).item()
    True
    >>> about_wrist([1.0, 0.0, 0.0], [0.0, 0.0, 0.0]).item(), about_wrist([0.0] * 3, [0.0] * 3).item()
    (False, False)
    """
    moves = off_tangent_moves(x, y, tol)
    return ~moves[..., :3, :].any(axis=(-2, -1)) & moves[..., 3:, :].any(axis=(-2, -1))


def normal_angles(normals, surface_normals):
    """The angle between each given normal and the object's surface normal there, in degrees.

    .. math::

        \\theta_i = \\operatorname{atan2}(\\lVert \\hat n_i \\times \\hat s_i \\rVert, \\hat n_i \\cdot \\hat s_i)

    (accurate near 0 and 180 degrees, where the arccosine of the dot product is not).

    Parameters
    ----------
    normals, surface_normals : (..., 3) arrays
        Unit vectors: a contact's normal as given and the surface's inward one at its point.

    Returns
    -------
    (...) array
        Degrees in ``[0, 180]``; NaN where an input is.

    >>> normal_angles([[1.0, 0, 0], [0, 1, 0]], [[1.0, 0, 0], [0, 0, 1]]).tolist()
    [0.0, 90.0]
    """
    n, s = np.asarray(normals, dtype=float), np.asarray(surface_normals, dtype=float)
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(n, s), axis=-1), dot(n, s)))


def outward_contacts(points, normals, center=None, tol=IN_PLANE_TOL):
    """Which normals point out of the object: away from its centre of mass, or else from the other contacts.

    Grasp files give normals pointing into the object.  Where the centre of
    mass ``c`` is known it lies inside the object, on the inner side of each
    contact's tangent plane on a convex object, so contact ``i``'s normal
    points outward when

    .. math::

        \\hat n_i \\cdot \\widehat{(c - p_i)} < -\\mathrm{tol}.

    Without it, the other contacts stand in for the object: on a convex
    object they lie on the inner side of the tangent plane too, so the normal
    points outward when no other contact lies on its inner side and one lies
    on its outer side:

    .. math::

        \\max_{j \\ne i} \\hat n_i \\cdot \\widehat{(p_j - p_i)} \\le \\mathrm{tol}, \\qquad
        \\min_{j \\ne i} \\hat n_i \\cdot \\widehat{(p_j - p_i)} < -\\mathrm{tol}.

    Each is a test of cosines, so the same for a grasp scaled or moved
    anywhere (lengths from about 1e-150 to 1e150), and directions at right
    angles within ``tol`` count as neither side.  Fingers pushing outward
    from inside a hollow (or a handle) are the grasps where an outward
    normal is meant.

    Parameters
    ----------
    points, normals : (..., 3, 3) arrays
        Contacts (contact, xyz) and their normals (any non-zero length).
    center : (..., 3) array, optional
        The centre of mass; NaN rows (or None) where there is none.
    tol : float
        Cosines within ``tol`` of 0 are round-off.

    Returns
    -------
    (..., 3) bool
        False where an input is NaN or a cosine has no direction (a contact at the centre of mass).

    Examples
    --------
    Paper Example 1 (normals into the cylinder), then the same with the normal at contact 2 reversed,
    then judged by a centre of mass below contact 1:

    >>> p = np.array([[1.0, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]])
    >>> outward_contacts(p, -p).tolist(), outward_contacts(p, -p * [[1], [-1], [1]]).tolist()
    ([False, False, False], [False, True, False])
    >>> outward_contacts(p, [[0, 0, 1.0], [0, 0, 1], [0, 0, 1]], center=[1.0, 0, -1]).tolist()
    [True, True, True]
    """
    points, normals = np.asarray(points, dtype=float), np.asarray(normals, dtype=float)
    with np.errstate(all="ignore"):  # NaN input: no verdict; lengths beyond 1e150 overflow to none either
        n_len = np.sqrt(dot(normals, normals))
        side = np.roll(points, -1, axis=-2) - points  # side i: p_{i+1} - p_i, so p_{i-1} - p_i is -side (i-1)
        side_len = np.sqrt(dot(side, side))
        ahead, behind = dot(normals, side), -dot(normals, np.roll(side, 1, axis=-2))
        ahead_tol, behind_tol = tol * n_len * side_len, tol * n_len * np.roll(side_len, 1, axis=-1)
        inside = (ahead > ahead_tol) | (behind > behind_tol)
        out = ~inside & ((ahead < -ahead_tol) | (behind < -behind_tol))
        if center is None:
            return out
        center = np.asarray(center, dtype=float)[..., None, :]
        toward = center - points
        away = dot(normals, toward) < -tol * n_len * np.sqrt(dot(toward, toward))
    return np.where(np.isnan(center).any(axis=-1), out, away)


def rotation_over_pi(rotvec):
    """Whether a rotation vector turns by more than pi: most likely degrees taken for radians.

    .. math:: \\lvert r \\rvert > \\pi

    A rotation vector ``r`` turns by ``|r|`` radians about ``r``; beyond pi
    it is the rotation by ``|r| - 2 pi k`` for some ``k``, so a pose target
    given by it is reached by the shorter turn (``[0, 0, 90]`` turns 116.6
    degrees).  Nobody writes a half turn and more that way on purpose.

    Parameters
    ----------
    rotvec : (..., 3) array

    Returns
    -------
    (...) bool
        False where the vector is NaN.

    >>> rotation_over_pi([[0, 0, 90], [0, 0, np.pi], [0, 3, 2]]).tolist()
    [True, False, True]
    """
    r = np.asarray(rotvec, dtype=float)
    return np.sqrt(dot(r, r)) > np.pi
