r"""The paper's formulas, one small function each, written to be read.

These are the definitions: basis lines built with
:func:`~grasptwist.engine.screws.line_through` and amplitudes as ratios of
Klein products (:func:`~grasptwist.engine.screws.klein`), exactly as the
paper writes them.  The engine computes the same numbers in closed form
(:mod:`~grasptwist.engine.kernels`), faster and with degeneracy checks; the
tests hold the two equal on random grasps.  Nothing here handles a
degenerate grasp: it gives NaN or infinities.

Conventions (README, "Conventions"): screws are ``(omega; v)``, ``v`` the
velocity of the point at the origin; basis screws are unit lines; ``(i, j,
k)`` runs cyclically over the contacts (:data:`~grasptwist.engine.screws.J`,
:data:`~grasptwist.engine.screws.K`).  Shapes: ``points`` and ``normals``
``(..., 3, 3)`` (contact, xyz), ``wrist`` ``(..., 3)``, ``twist`` ``(..., 6)``,
a basis ``(..., 3, 6)`` (screw ``i``, six numbers).  The examples are the
paper's, with the corrected numbers of the README ("Conventions").
"""

from __future__ import annotations

import numpy as np

from .screws import J, K, cross, klein, line_through

__all__ = [
    "sigma_lines",
    "psi_lines",
    "theta_lines",
    "normal_lines",
    "off_tangent_amplitudes",
    "tangent_amplitudes",
    "normal_velocities",
]

# Paper Example 1 (a cylinder held at three points of a circle, wrist above;
# the paper rounds sqrt(3)/2 to 0.866) and Example 2 (a polyhedron touched on
# three perpendicular faces).
_EX1 = [[1, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]]
_EX2 = [[0, 2, 2], [2, 0, 2], [2, 2, 0]]


def sigma_lines(points):
    r"""The screws ``Sigma_i``: the unit line through ``p_j`` and ``p_k`` (eq. 8).

    .. math::

        \Sigma_i = \left(\hat u_i;\; p_j \times \hat u_i\right), \qquad
        \hat u_i = \frac{p_k - p_j}{\lvert p_k - p_j \rvert},

    so that :math:`\Sigma_i(p_j) = \Sigma_i(p_k) = 0`: ``Sigma_i`` moves
    contact ``i`` alone.  ``(..., 3, 3) -> (..., 3, 6)``.

    Example 1: ``Sigma_1`` is the line through ``p_2`` and ``p_3``:

    >>> (sigma_lines(_EX1)[0].round(4) + 0.0).tolist()
    [0.0, -1.0, 0.0, 0.0, 0.0, 0.5]
    """
    p = np.asarray(points, dtype=float)
    return line_through(p[..., J, :], p[..., K, :] - p[..., J, :])


def psi_lines(points, wrist):
    r"""The screws ``Psi_i``: the unit line from the wrist ``c`` through ``p_i`` (eq. 11).

    .. math::

        \Psi_i = \left(\hat e_i;\; p_i \times \hat e_i\right), \qquad
        \hat e_i = \frac{p_i - c}{\lvert p_i - c \rvert},

    so that :math:`\Psi_i(p_i) = \Psi_i(c) = 0`: ``Psi_i`` keeps contact
    ``i`` (and the wrist) fixed.  ``(..., 3, 3), (..., 3) -> (..., 3, 6)``.

    Example 1, wrist ``c = (0, 0, 1)`` (the paper prints ``Psi_1`` unnormalised):

    >>> (psi_lines(_EX1, [0, 0, 1])[0].round(4) + 0.0).tolist()
    [0.7071, 0.0, -0.7071, 0.0, 0.7071, 0.0]
    """
    p = np.asarray(points, dtype=float)
    return line_through(p, p - np.asarray(wrist, dtype=float)[..., None, :])


def theta_lines(points, normals):
    r"""The screws ``Theta_i``: the unit line through ``p_i`` along ``omega_i`` of eq. 22.

    .. math::

        \omega_i = \left(n_j \times \overrightarrow{p_i p_j}\right) \times
                   \left(n_k \times \overrightarrow{p_i p_k}\right), \qquad
        \Theta_i = \left(\hat\omega_i;\; p_i \times \hat\omega_i\right).

    ``Theta_i`` keeps ``p_i`` fixed and moves ``p_j``, ``p_k`` within their
    tangent planes (eqs. 20-21).  ``(..., 3, 3), (..., 3, 3) -> (..., 3, 6)``.

    Example 2 (the paper prints a wrong sign in ``Theta_1``):

    >>> (theta_lines(_EX2, np.eye(3))[0] + 0.0).tolist()
    [1.0, 0.0, 0.0, 0.0, 2.0, -2.0]
    """
    p = np.asarray(points, dtype=float)
    n = np.asarray(normals, dtype=float)
    pj, pk = p[..., J, :], p[..., K, :]
    omega = cross(cross(n[..., J, :], pj - p), cross(n[..., K, :], pk - p))
    return line_through(p, omega)


def normal_lines(points, normals):
    r"""The screws ``nu_i``: the unit line through ``p_i`` along its normal.

    .. math:: \nu_i = \left(\hat n_i;\; p_i \times \hat n_i\right)

    ``(..., 3, 3), (..., 3, 3) -> (..., 3, 6)``.  The tangent method needs
    them of rank 3 (Proposition 2).

    >>> (normal_lines(_EX2, np.eye(3))[2] + 0.0).tolist()
    [0.0, 0.0, 1.0, 2.0, -2.0, 0.0]
    """
    return line_through(np.asarray(points, dtype=float), normals)


def normal_velocities(points, normals, twist):
    r"""The speed of each contact along its unit normal (the equation before eq. 19).

    .. math:: [T \mid \nu_i] = T(p_i) \cdot \hat n_i

    All three are zero exactly when ``T`` keeps every contact in its tangent
    plane (eq. 19).  ``(..., 3, 3), (..., 3, 3), (..., 6) -> (..., 3)``.

    Example 2: a lift along z pushes contact 3 off its plane only:

    >>> (normal_velocities(_EX2, np.eye(3), [0, 0, 0, 0, 0, 1]) + 0.0).tolist()
    [0.0, 0.0, 1.0]
    """
    return klein(np.asarray(twist, dtype=float)[..., None, :], normal_lines(points, normals))


def off_tangent_amplitudes(sigma, psi, twist):
    r"""Proposition 1: the amplitudes ``x``, ``y`` of ``T = sum x_i Sigma_i + sum y_i Psi_i`` (eq. 14).

    .. math::

        x_i = \frac{[T \mid \Psi_i]}{[\Sigma_i \mid \Psi_i]}, \qquad
        y_i = \frac{[T \mid \Sigma_i]}{[\Sigma_i \mid \Psi_i]}

    valid because ``[Sigma_i|Sigma_j]``, ``[Sigma_i|Psi_j]`` and
    ``[Psi_i|Psi_j]`` vanish for ``i != j`` (eq. 13).
    ``(..., 3, 6), (..., 3, 6), (..., 6) -> (..., 3), (..., 3)``.

    Example 1: ``[Sigma_i|Psi_i] = -1.0607`` (eq. 18); a spin about z is
    made by the ``Psi`` alone, a lift along z by the ``Sigma`` alone:

    >>> sigma, psi = sigma_lines(_EX1), psi_lines(_EX1, [0, 0, 1])
    >>> klein(sigma, psi).round(4).tolist()
    [-1.0607, -1.0607, -1.0607]
    >>> x, y = off_tangent_amplitudes(sigma, psi, [0, 0, 1, 0, 0, 0])
    >>> (x.round(4) + 0.0).tolist(), y.round(4).tolist()
    ([0.0, 0.0, 0.0], [-0.4714, -0.4714, -0.4714])
    >>> x, y = off_tangent_amplitudes(sigma, psi, [0, 0, 0, 0, 0, 1])
    >>> x.round(4).tolist(), (y.round(4) + 0.0).tolist()
    ([0.6667, 0.6667, 0.6667], [0.0, 0.0, 0.0])
    """
    t = np.asarray(twist, dtype=float)[..., None, :]
    sigma_psi = klein(sigma, psi)
    return klein(t, psi) / sigma_psi, klein(t, sigma) / sigma_psi


def tangent_amplitudes(theta, sigma, twist):
    r"""Proposition 2 and the off-plane rest: ``T = sum alpha_i Theta_i + sum beta_i Sigma_i``.

    ``alpha`` by eq. 27; the rest ``R`` is reciprocal to every ``Sigma_i``,
    so it lies in their span (README, "The tangent method beyond the
    paper"), and ``[Sigma_j|Theta_i] = 0`` for ``j != i`` (eq. 26) gives
    ``beta``:

    .. math::

        \alpha_i = \frac{[T \mid \Sigma_i]}{[\Theta_i \mid \Sigma_i]}, \qquad
        R = T - \sum_j \alpha_j \Theta_j, \qquad
        \beta_i = \frac{[R \mid \Theta_i]}{[\Sigma_i \mid \Theta_i]}.

    ``beta = 0`` exactly when ``T`` keeps every contact in its tangent plane.
    ``(..., 3, 6), (..., 3, 6), (..., 6) -> (..., 3), (..., 3)``.

    Example 2: the spin about the diagonal is tangent sliding alone:

    >>> theta, sigma = theta_lines(_EX2, np.eye(3)), sigma_lines(_EX2)
    >>> alpha, beta = tangent_amplitudes(theta, sigma, [0.57735, 0.57735, 0.57735, 0, 0, 0])
    >>> alpha.round(4).tolist(), (beta.round(4) + 0.0).tolist()
    ([0.5774, 0.5774, 0.5774], [0.0, 0.0, 0.0])
    """
    theta = np.asarray(theta, dtype=float)
    t = np.asarray(twist, dtype=float)
    alpha = klein(t[..., None, :], sigma) / klein(theta, sigma)
    rest = t - np.sum(alpha[..., None] * theta, axis=-2)
    beta = klein(rest[..., None, :], theta) / klein(sigma, theta)
    return alpha, beta
