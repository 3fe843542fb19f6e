"""Judgements on a resolved twist: which fingers each component moves, and
whether the twist is a rotation about the wrist; and on a grasp: whether
its normals look outward.

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

__all__ = ["ALONE", "ALL_BUT", "active", "off_tangent_moves", "tangent_moves", "about_wrist", "outward_normals"]

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


def outward_normals(points, normals, tol=IN_PLANE_TOL):
    """Whether every normal points away from the other contacts (outward, on a convex object).

    Grasp files give normals pointing into the object.  On a convex object
    the other contacts then lie on the inner side of each contact's tangent
    plane, so a grasp whose three normals all point away from the contacts'
    centroid ``g`` most likely has them reversed (or the fingers push
    outward from inside a hollow, the one grasp where that is meant):

    .. math::

        \\hat n_i \\cdot \\widehat{(g - p_i)} < -\\mathrm{tol}
        \\quad \\text{for } i = 1, 2, 3, \\qquad g = \\tfrac13 \\textstyle\\sum_j p_j

    It is a test of the cosine between the two, so the same for a grasp
    scaled or moved anywhere (lengths from about 1e-150 to 1e150), and
    normals at right angles to ``g - p_i`` (within ``tol``) do not count as
    outward.

    Parameters
    ----------
    points, normals : (..., 3, 3) arrays
        Contacts (contact, xyz) and their normals (any non-zero length).
    tol : float
        Cosines down to ``-tol`` are round-off.

    Returns
    -------
    (...) bool
        False where a contact is at the centroid (its cosine is 0) or an input is NaN.

    Examples
    --------
    Paper Example 1 (normals into the cylinder), then the same reversed:

    >>> p = np.array([[1.0, 0, 0], [-0.5, 0.866, 0], [-0.5, -0.866, 0]])
    >>> outward_normals(p, -p).item(), outward_normals(p, p).item()
    (False, True)
    """
    points, normals = np.asarray(points, dtype=float), np.asarray(normals, dtype=float)
    toward = points.mean(axis=-2, keepdims=True) - points
    with np.errstate(all="ignore"):  # NaN input: no verdict; lengths beyond 1e150 overflow to none either
        lengths = np.sqrt(dot(normals, normals) * dot(toward, toward))
        return np.all(dot(normals, toward) < -tol * lengths, axis=-1)
