r"""The grip's set-up, written once for the numpy path and the compiled one: the contacts' geometry, ``G^+ w``,
the cones, a squeeze strictly inside them and the start it gives, the culprit of a grip that fails.

Lane form, as :mod:`~grasptwist.engine.forces.ipm`'s iteration is: each array's last axis is the
rows (the lanes), and a loop ``for ln in range(width):`` does one row's straight-line arithmetic
(no ``if``; choices ``a if c else b``).  numba compiles these functions
(:mod:`~grasptwist.engine.forces.kernel`: each row's arrays a lane of width 1), and numpy runs
their twins on all the rows at once (:func:`twins`, :func:`on_rows`, :mod:`~grasptwist.engine.forces._twin`):
:func:`grasp_map.geometry`, :func:`~grasp_map.unit_normals`, ``G^+ w``, the cones' frames and
problems of :mod:`~grasptwist.engine.forces.grip`, its start and culprit, the dual twist, and the
closure test of :mod:`~grasptwist.engine.forces.closure` are these functions' twins; one grasp's
float path (:func:`one.solve`) runs the start's and the culprit's float twins.  So the paths share
every formula of the set-up, as they share the iteration's.

The formulas (a grasp ``p (3, 3)``, rows the contacts):

* centroid ``g``, ``q_i = p_i - g``, ``t = sum |q_i|^2``, ``m = (p_2 - p_1) x (p_3 - p_1)`` and the
  conditioning ``sqrt(2 lambda_min / t)`` of ``sum q_i q_i^T`` (:func:`contact_geometry`);
* ``G^+ w`` and the twist nearest a field of forces (:func:`manipulating`, :func:`twist_through`),
  through ``J^{-1}`` in closed form (:mod:`~grasptwist.engine.forces.grasp_map`'s docstring);
* each cone's frame ``F_i = (n_i; b_i / mu_i; t_i / mu_i)`` and the problem ``A_i = F_i M_i``,
  ``b_i = F_i f_i`` of :mod:`~grasptwist.engine.forces.socp` (:func:`cone_frames`, :func:`cone_rows`);
* the closure test of the squeezes (:func:`closure_test`): a squeeze strictly inside every cone,
  in the contacts' plane (:func:`plane_reduction`, :func:`sector_rows`, :func:`internal_inside`).

Arrays: ``p, n (3, 3, width)`` (contact, xyz), ``w (6, width)``, ``limit (3, width)`` (``mu / s_f``).
"""

from __future__ import annotations

import functools
from itertools import combinations

import numpy as np

from .ipm import START_MARGIN, every, lanes

__all__ = [
    "CLOSURE_PAIRS",
    "STRICT_MARGIN",
    "ROUND_OFF",
    "LANE_FORM",
    "twins",
    "lanes",
    "on_rows",
    "tangents",
    "own_sectors",
    "contact_geometry",
    "squeeze_directions",
    "unit_normals",
    "manipulating",
    "twist_through",
    "cone_frames",
    "squeeze_map",
    "cone_rows",
    "plane_reduction",
    "sector_rows",
    "closure_test",
    "internal_inside",
    "inside_workspace",
    "start",
    "culprit",
    "pulling_possible",
]

#: The closure test's pairs of its six unit rows ``R`` (two a contact) whose cross products are the candidate rays.
CLOSURE_PAIRS = np.array(list(combinations(range(6), 2)))

#: The closure test's margin below which a row's or a direction's is not strict.
STRICT_MARGIN = 1e-12

#: A normal's component along a unit internal force at most this is round-off of 0 (:func:`cone_rows`).
ROUND_OFF = 1e-12

# side i joins contacts _J[i] and _K[i] (screws.J, screws.K; arrays, so that the twins index them by a slice)
_J, _K = np.array((1, 2, 0)), np.array((2, 0, 1))

# a normal whose squared length is beyond these is first scaled by 2^-600 or 2^600 (exact), so that no finite
# normal's squares overflow or underflow; within them, n / |n| to the last bit
_HUGE, _TINY = 1e290, 1e-290
_DOWN, _UP = 2.0**-600, 2.0**600


def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


def contact_geometry(p, g, q, mv, sizes, width):
    """The centroid ``g (3, width)``, ``q (3, 3, width)``, ``m (3, width)`` and ``sizes (3, width)``: ``t``, the
    largest ``|q_i|^2`` and the conditioning ``sqrt(2 lambda_min / t)``, ``lambda_min`` the smaller in-plane
    eigenvalue of ``sum q_i q_i^T`` (whose product is ``|m|^2 / 3``), computed stably.

    >>> p = np.array([[1.0, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])[..., None]
    >>> g, q, m, sizes = np.empty((3, 1)), np.empty((3, 3, 1)), np.empty((3, 1)), np.empty((3, 1))
    >>> contact_geometry(p, g, q, m, sizes, 1); sizes[:, 0].round(12).tolist()
    [3.0, 1.0, 1.0]
    """
    for k in every(3):
        for ln in range(width):
            g[k, ln] = (p[0, k, ln] + p[1, k, ln] + p[2, k, ln]) / 3
    for i in every(3):
        for k in every(3):
            for ln in range(width):
                q[i, k, ln] = p[i, k, ln] - g[k, ln]
    for ln in range(width):
        t, top = 0.0, 0.0
        for i in range(3):
            q2 = q[i, 0, ln] * q[i, 0, ln] + q[i, 1, ln] * q[i, 1, ln] + q[i, 2, ln] * q[i, 2, ln]
            t += q2
            top = np.maximum(top, q2)
        m0, m1, m2 = _cross(
            p[1, 0, ln] - p[0, 0, ln],
            p[1, 1, ln] - p[0, 1, ln],
            p[1, 2, ln] - p[0, 2, ln],
            p[2, 0, ln] - p[0, 0, ln],
            p[2, 1, ln] - p[0, 1, ln],
            p[2, 2, ln] - p[0, 2, ln],
        )
        mv[0, ln], mv[1, ln], mv[2, ln] = m0, m1, m2
        det = (m0 * m0 + m1 * m1 + m2 * m2) / 3
        small = 2 * det / (t + np.sqrt(np.maximum(t * t - 4 * det, 0.0)))
        sizes[0, ln], sizes[1, ln], sizes[2, ln] = t, top, np.sqrt(2 * small / t)


def squeeze_directions(p, e, side, width):
    """``e_i = (p_k - p_j) / |p_k - p_j|`` into ``e (3, 3, width)`` (the axis of ``Sigma_i``, eq. 8) and the
    sides' lengths into ``side (3, width)``."""
    for i in every(3):
        for ln in range(width):
            a, c = _J[i], _K[i]
            e0, e1, e2 = p[c, 0, ln] - p[a, 0, ln], p[c, 1, ln] - p[a, 1, ln], p[c, 2, ln] - p[a, 2, ln]
            length = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
            side[i, ln] = length
            e[i, 0, ln], e[i, 1, ln], e[i, 2, ln] = e0 / length, e1 / length, e2 / length


def unit_normals(n, unit, width):
    """``n_i / |n_i|`` into ``unit (3, 3, width)``: NaN for a zero normal, not finite for a non-finite one.  A
    normal whose squares would overflow or underflow is scaled by a power of two first (exact: the same
    direction)."""
    for i in every(3):
        for ln in range(width):
            n0, n1, n2 = n[i, 0, ln], n[i, 1, ln], n[i, 2, ln]
            squares = n0 * n0 + n1 * n1 + n2 * n2
            scale = _DOWN if squares > _HUGE else (_UP if squares < _TINY else 1.0)
            n0, n1, n2 = n0 * scale, n1 * scale, n2 * scale
            length = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
            unit[i, 0, ln], unit[i, 1, ln], unit[i, 2, ln] = n0 / length, n1 / length, n2 / length


def _spin(q, mv, t, x0, x1, x2, ln):
    """``J^-1 x``, ``J = sum_i (|q_i|^2 I - q_i q_i^T)``: ``(m (m . x) / t + 3 sum_i q_i (q_i . x)) / |m|^2``."""
    s0, s1, s2 = 0.0, 0.0, 0.0
    for i in range(3):
        qx = q[i, 0, ln] * x0 + q[i, 1, ln] * x1 + q[i, 2, ln] * x2
        s0, s1, s2 = s0 + q[i, 0, ln] * qx, s1 + q[i, 1, ln] * qx, s2 + q[i, 2, ln] * qx
    mm = mv[0, ln] * mv[0, ln] + mv[1, ln] * mv[1, ln] + mv[2, ln] * mv[2, ln]
    mx = (mv[0, ln] * x0 + mv[1, ln] * x1 + mv[2, ln] * x2) / t
    return (mv[0, ln] * mx + 3 * s0) / mm, (mv[1, ln] * mx + 3 * s1) / mm, (mv[2, ln] * mx + 3 * s2) / mm


def manipulating(g, q, mv, sizes, w, fm, omega, width):
    r"""``G^+ w`` into ``fm (3, 3, width)``: ``f_i = F / 3 + omega x q_i``, ``omega = J^-1 (M - g x F)`` (into
    ``omega (3, width)``).

    >>> p = np.array([[1.0, 0, 0], [-0.5, 0.75**0.5, 0], [-0.5, -(0.75**0.5), 0]])[..., None]
    >>> g, q, m, sizes, fm = np.empty((3, 1)), np.empty((3, 3, 1)), np.empty((3, 1)), np.empty((3, 1)), np.empty((3, 3, 1))
    >>> contact_geometry(p, g, q, m, sizes, 1)
    >>> manipulating(g, q, m, sizes, np.array([0, 0, 3.0, 0, 0, 0])[:, None], fm, np.empty((3, 1)), 1)
    >>> fm[:, 2, 0].tolist()
    [1.0, 1.0, 1.0]
    """
    for ln in range(width):
        F0, F1, F2 = w[0, ln], w[1, ln], w[2, ln]
        c0, c1, c2 = _cross(g[0, ln], g[1, ln], g[2, ln], F0, F1, F2)
        o0, o1, o2 = _spin(q, mv, sizes[0, ln], w[3, ln] - c0, w[4, ln] - c1, w[5, ln] - c2, ln)
        omega[0, ln], omega[1, ln], omega[2, ln] = o0, o1, o2
    for i in every(3):
        for ln in range(width):
            d0, d1, d2 = _cross(omega[0, ln], omega[1, ln], omega[2, ln], q[i, 0, ln], q[i, 1, ln], q[i, 2, ln])
            fm[i, 0, ln] = w[0, ln] / 3 + d0
            fm[i, 1, ln] = w[1, ln] / 3 + d1
            fm[i, 2, ln] = w[2, ln] / 3 + d2


def twist_through(g, q, mv, sizes, d, out, width):
    """The twist ``out (6, width)`` whose field ``v + omega x p_i`` is nearest ``d_i`` (least squares, ``d (3, 3,
    width)``): about the centroid ``v = mean(d) - omega x g``, ``J omega = sum_i q_i x d_i``."""
    for ln in range(width):
        x0, x1, x2 = 0.0, 0.0, 0.0
        for i in range(3):
            c0, c1, c2 = _cross(q[i, 0, ln], q[i, 1, ln], q[i, 2, ln], d[i, 0, ln], d[i, 1, ln], d[i, 2, ln])
            x0, x1, x2 = x0 + c0, x1 + c1, x2 + c2
        o0, o1, o2 = _spin(q, mv, sizes[0, ln], x0, x1, x2, ln)
        c0, c1, c2 = _cross(o0, o1, o2, g[0, ln], g[1, ln], g[2, ln])
        out[0, ln] = (d[0, 0, ln] + d[1, 0, ln] + d[2, 0, ln]) / 3 - c0
        out[1, ln] = (d[0, 1, ln] + d[1, 1, ln] + d[2, 1, ln]) / 3 - c1
        out[2, ln] = (d[0, 2, ln] + d[1, 2, ln] + d[2, 2, ln]) / 3 - c2
        out[3, ln], out[4, ln], out[5, ln] = o0, o1, o2


def tangents(u0, u1, u2):
    """Two unit tangents ``b_1 = n x e / |n x e|`` (``e`` the x axis, or the y axis where ``|n_x| >= 0.9``) and
    ``b_2 = n x b_1`` of a unit normal, as six numbers."""
    x_axis = np.abs(u0) < 0.9
    b0, b1, b2 = _cross(u0, u1, u2, 1.0 if x_axis else 0.0, 0.0 if x_axis else 1.0, 0.0)
    length = np.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
    b0, b1, b2 = b0 / length, b1 / length, b2 / length
    t0, t1, t2 = _cross(u0, u1, u2, b0, b1, b2)
    return b0, b1, b2, t0, t1, t2


def cone_frames(unit, limit, frame, width):
    """Each contact's cone as ``frame (3, 3, 3, width)``: ``F_i = (n_i; b_i / limit_i; t_i / limit_i)`` (rows), so the
    force ``f`` is in the cone ``|f_t| <= limit_i f_n`` where ``F_i f`` is in ``Q^3`` (an infinite limit: 0)."""
    for i in every(3):
        for ln in range(width):
            kappa = 0.0 if np.isinf(limit[i, ln]) else 1 / limit[i, ln]
            u0, u1, u2 = unit[i, 0, ln], unit[i, 1, ln], unit[i, 2, ln]
            b0, b1, b2, t0, t1, t2 = tangents(u0, u1, u2)
            frame[i, 0, 0, ln], frame[i, 0, 1, ln], frame[i, 0, 2, ln] = u0, u1, u2
            frame[i, 1, 0, ln], frame[i, 1, 1, ln], frame[i, 1, 2, ln] = kappa * b0, kappa * b1, kappa * b2
            frame[i, 2, 0, ln], frame[i, 2, 1, ln], frame[i, 2, 2, ln] = kappa * t0, kappa * t1, kappa * t2


def squeeze_map(e, M, width):
    """``M (3, 3, 3, width)``: ``M[i, :, l]`` the force on contact ``i`` of a unit squeeze ``l``, ``e_l`` on the first
    contact of side ``l`` and ``-e_l`` on its second (``M[i, :, i] = 0``)."""
    for i in range(3):
        a, c = _J[i], _K[i]
        for x in every(3):
            for ln in range(width):
                M[i, x, c, ln] = e[c, x, ln]
                M[i, x, a, ln] = -e[a, x, ln]
                M[i, x, i, ln] = 0.0


def cone_rows(frame, M, fm, scale, A, b, d, width):
    """The method's rows ``A_i = F_i M_i`` (``A (3, 3, d, width)``, ``M (3, 3, d, width)``: the internal forces' map,
    ``d`` unknowns) and ``b_i = F_i f_i / scale`` (``b (3, 3, width)``).

    A normal row's entry is a unit normal's dot product with a unit internal force: at most
    :data:`ROUND_OFF` it is round-off of a normal perpendicular to that force (a contact no squeeze
    pushes, in a rotated frame), and exactly 0, as it is unrotated.  Left at ``1e-16``, it let an infinite
    friction's half-space hold with squeezes of ``1e16`` and the pulling test call the row regular, so the
    verdicts turned with the grasp's frame."""
    for k in range(3):
        for i in every(3):
            for ln in range(width):
                b[i, k, ln] = (
                    frame[i, k, 0, ln] * (fm[i, 0, ln] / scale[ln])
                    + frame[i, k, 1, ln] * (fm[i, 1, ln] / scale[ln])
                    + frame[i, k, 2, ln] * (fm[i, 2, ln] / scale[ln])
                )
            for j in range(d):
                for ln in range(width):
                    t = frame[i, k, 0, ln] * M[i, 0, j, ln] + frame[i, k, 1, ln] * M[i, 1, j, ln]
                    t += frame[i, k, 2, ln] * M[i, 2, j, ln]
                    A[i, k, j, ln] = t if (k > 0) | (np.abs(t) > ROUND_OFF) else 0.0


def plane_reduction(p, unit, mv, M, axes, tilt, dirs, forces, width):
    """The closure test's reduction to the contacts' plane, its unit normal ``nu`` and axes ``x`` along
    ``p_2 - p_1``, ``y = nu x x`` (into ``axes (3, 3, width)``): ``tilt (2, 3, width)`` each normal's ``|sin|``
    and ``cos`` to the plane, ``dirs (3, 2, width)`` its unit direction in the plane, ``forces (3, 3, 2,
    width)`` (contact, squeeze, xy) the squeezes' forces in the plane (``M``: :func:`squeeze_map`'s)."""
    for ln in range(width):
        length = np.sqrt(mv[0, ln] * mv[0, ln] + mv[1, ln] * mv[1, ln] + mv[2, ln] * mv[2, ln])
        n0, n1, n2 = mv[0, ln] / length, mv[1, ln] / length, mv[2, ln] / length
        x0, x1, x2 = p[1, 0, ln] - p[0, 0, ln], p[1, 1, ln] - p[0, 1, ln], p[1, 2, ln] - p[0, 2, ln]
        length = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
        x0, x1, x2 = x0 / length, x1 / length, x2 / length
        y0, y1, y2 = _cross(n0, n1, n2, x0, x1, x2)
        axes[0, 0, ln], axes[0, 1, ln], axes[0, 2, ln] = n0, n1, n2
        axes[1, 0, ln], axes[1, 1, ln], axes[1, 2, ln] = x0, x1, x2
        axes[2, 0, ln], axes[2, 1, ln], axes[2, 2, ln] = y0, y1, y2
    for i in every(3):
        for ln in range(width):
            n0, n1, n2 = axes[0, 0, ln], axes[0, 1, ln], axes[0, 2, ln]
            x0, x1, x2 = axes[1, 0, ln], axes[1, 1, ln], axes[1, 2, ln]
            y0, y1, y2 = axes[2, 0, ln], axes[2, 1, ln], axes[2, 2, ln]
            un = unit[i, 0, ln] * n0 + unit[i, 1, ln] * n1 + unit[i, 2, ln] * n2
            sin = np.abs(un)
            tilt[0, i, ln], tilt[1, i, ln] = sin, np.sqrt(np.maximum(1 - sin * sin, 0.0))
            p0, p1, p2 = unit[i, 0, ln] - un * n0, unit[i, 1, ln] - un * n1, unit[i, 2, ln] - un * n2
            a, c = p0 * x0 + p1 * x1 + p2 * x2, p0 * y0 + p1 * y1 + p2 * y2
            h = np.sqrt(a * a + c * c)
            dirs[i, 0, ln], dirs[i, 1, ln] = a / h, c / h
            for sq in range(3):
                forces[i, sq, 0, ln] = M[i, 0, sq, ln] * x0 + M[i, 1, sq, ln] * x1 + M[i, 2, sq, ln] * x2
                forces[i, sq, 1, ln] = M[i, 0, sq, ln] * y0 + M[i, 1, sq, ln] * y1 + M[i, 2, sq, ln] * y2


def sector_rows(dirs, forces, sin_beta, cos_beta, rows, width):
    """The six unit rows ``R (3, 2, 3, width)`` (contact, edge, squeeze) of the sectors of half-angles ``beta_i``
    (``(3, width)`` sines and cosines) about each normal's direction in the plane: a squeeze ``s`` is strictly
    inside contact ``i``'s sector where ``R[i, 0] s > 0`` and ``R[i, 1] s > 0``."""
    for edge in range(2):
        sign = -1.0 if edge == 0 else 1.0
        for i in every(3):
            for ln in range(width):
                m0, m1 = dirs[i, 0, ln], dirs[i, 1, ln]
                v0 = sin_beta[i, ln] * m0 - sign * cos_beta[i, ln] * m1
                v1 = sin_beta[i, ln] * m1 + sign * cos_beta[i, ln] * m0
                r0 = forces[i, 0, 0, ln] * v0 + forces[i, 0, 1, ln] * v1
                r1 = forces[i, 1, 0, ln] * v0 + forces[i, 1, 1, ln] * v1
                r2 = forces[i, 2, 0, ln] * v0 + forces[i, 2, 1, ln] * v1
                length = np.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
                rows[i, edge, 0, ln], rows[i, edge, 1, ln], rows[i, edge, 2, ln] = r0 / length, r1 / length, r2 / length


def closure_test(rows, rays, s, ok, width):
    """Whether ``R s > 0`` has a solution, and one, for unit rows ``R (6, 3, width)``: ``s (3, width)``, ``ok (width)``.

    The candidates are ``+-(r_a x r_b)`` (:data:`CLOSURE_PAIRS`); those inside the closed cone
    ``R s >= 0`` are its extreme rays (into ``rays (3, 15, width)``, 0 for the others), and their sum
    is strictly inside where anything is.

    >>> rows, rays, s, ok = np.array(np.eye(3).tolist() * 2)[..., None], np.empty((3, 15, 1)), np.empty((3, 1)), np.empty(1, bool)
    >>> with np.errstate(invalid="ignore"):  # a pair of equal rows: no candidate (its 0 / 0 discarded)
    ...     closure_test(rows, rays, s, ok, 1)
    >>> bool(ok[0]), s[:, 0].round(4).tolist()
    (True, [0.5774, 0.5774, 0.5774])
    """
    for pair in every(15):
        for ln in range(width):
            a, c = CLOSURE_PAIRS[pair, 0], CLOSURE_PAIRS[pair, 1]
            c0, c1, c2 = _cross(
                rows[a, 0, ln], rows[a, 1, ln], rows[a, 2, ln], rows[c, 0, ln], rows[c, 1, ln], rows[c, 2, ln]
            )
            length = np.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
            real = length > STRICT_MARGIN
            c0, c1, c2 = c0 / length, c1 / length, c2 / length
            above, below = real, real
            for k in range(6):
                d = rows[k, 0, ln] * c0 + rows[k, 1, ln] * c1 + rows[k, 2, ln] * c2
                above = above & (d >= -STRICT_MARGIN)
                below = below & (d <= STRICT_MARGIN)
            sign = (1.0 if above else 0.0) - (1.0 if below else 0.0)
            rays[0, pair, ln] = c0 * sign if real else 0.0
            rays[1, pair, ln] = c1 * sign if real else 0.0
            rays[2, pair, ln] = c2 * sign if real else 0.0
    for ln in range(width):
        s0, s1, s2 = rays[0, 0, ln], rays[1, 0, ln], rays[2, 0, ln]
        for pair in range(1, 15):
            s0, s1, s2 = s0 + rays[0, pair, ln], s1 + rays[1, pair, ln], s2 + rays[2, pair, ln]
        length = np.sqrt(s0 * s0 + s1 * s1 + s2 * s2)
        s0, s1, s2 = s0 / length, s1 / length, s2 / length
        s[0, ln], s[1, ln], s[2, ln] = s0, s1, s2
        good = length > STRICT_MARGIN
        for k in range(6):
            good = good & (rows[k, 0, ln] * s0 + rows[k, 1, ln] * s1 + rows[k, 2, ln] * s2 > STRICT_MARGIN)
        ok[ln] = good


def own_sectors(tilt, limit, sin_beta, cos_beta, reach, width):
    """The sectors in the plane of the cones ``|f_t| <= limit_i f_n`` (half-angle ``theta_i = atan(limit_i)``, the
    normal at ``phi_i`` to the plane): ``sin^2 beta_i = (sin^2 theta_i - sin^2 phi_i) / cos^2 phi_i``,
    ``cos beta_i = min(cos theta_i / cos phi_i, 1)``, without the angles (as a product that keeps small
    angles exact; a huge or infinite limit a half-plane), and ``reach (width)``: whether every cone reaches
    the plane (``theta_i > phi_i``, ``cos phi_i > 0``)."""
    for ln in range(width):
        reach[ln] = True
    for i in range(3):
        for ln in range(width):
            radius = np.hypot(1.0, limit[i, ln])
            sin_theta = 1.0 if np.isinf(limit[i, ln]) else limit[i, ln] / radius
            sin_phi, cos = np.minimum(tilt[0, i, ln], 1.0), tilt[1, i, ln]
            reach[ln] = reach[ln] & (sin_theta > sin_phi) & (cos > 0)
            sin_beta[i, ln] = np.sqrt(np.maximum((sin_theta - sin_phi) * (sin_theta + sin_phi), 0.0)) / cos
            cos_beta[i, ln] = np.minimum(1 / radius / cos, 1.0)


def internal_inside(p, unit, mv, M, limit, out, work, width):
    """A unit squeeze strictly inside every cone ``limit (3, width)`` into ``out (3, width)``, NaN where there is none
    (the contacts not in force closure with their limits): :func:`own_sectors`' rows through :func:`closure_test`
    (``M``: :func:`squeeze_map`'s; ``work``: :func:`inside_workspace`'s arrays)."""
    axes, tilt, dirs, forces, sin_beta, cos_beta, reach, rows, rays, ok = work
    plane_reduction(p, unit, mv, M, axes, tilt, dirs, forces, width)
    own_sectors(tilt, limit, sin_beta, cos_beta, reach, width)
    sector_rows(dirs, forces, sin_beta, cos_beta, rows, width)
    closure_test(rows.reshape((6, 3, width)), rays, out, ok, width)
    for k in every(3):
        for ln in range(width):
            out[k, ln] = out[k, ln] if ok[ln] & reach[ln] else np.nan


def inside_workspace(width):
    """:func:`internal_inside`'s arrays for ``width`` rows.

    >>> [w.shape for w in inside_workspace(2)][:3]
    [(3, 3, 2), (2, 3, 2), (3, 2, 2)]
    """
    sines = np.empty((2, 3, width))
    return (
        np.empty((3, 3, width)),  # axes
        np.empty((2, 3, width)),  # tilt
        np.empty((3, 2, width)),  # dirs
        np.empty((3, 3, 2, width)),  # forces
        sines[0],  # sin beta
        sines[1],  # cos beta
        np.empty(width, np.bool_),  # reach
        np.empty((3, 2, 3, width)),  # rows
        np.empty((3, 15, width)),  # rays
        np.empty(width, np.bool_),  # ok
    )


def start(A, b, inside, x, d, width):
    """Phase II's start from a squeeze strictly inside every cone: ``x (d, width)`` = ``inside (d, width)`` scaled
    so that each ``A_m x + b_m`` clears its cone by :data:`~ipm.START_MARGIN` (``A (3, 3, d, width)``,
    ``b (3, 3, width)``; NaN where ``inside`` is): ``max_m (START_MARGIN + |b_m0| + |b_mt|) / depth_m``,
    ``depth_m = y_m0 - |y_mt|`` of ``y_m = A_m inside`` (positive: strictly inside; else, a squeeze the closure
    test found inside the sectors but on a cone's edge, NaN: phase I finds the start)."""
    for ln in range(width):
        reach, ok = -np.inf, True
        for m in range(3):
            y0, y1, y2 = 0.0, 0.0, 0.0
            for j in range(d):
                y0 += A[m, 0, j, ln] * inside[j, ln]
                y1 += A[m, 1, j, ln] * inside[j, ln]
                y2 += A[m, 2, j, ln] * inside[j, ln]
            depth = y0 - np.sqrt(y1 * y1 + y2 * y2)
            span = START_MARGIN + np.abs(b[m, 0, ln]) + np.sqrt(b[m, 1, ln] * b[m, 1, ln] + b[m, 2, ln] * b[m, 2, ln])
            ok = ok & (depth > 0)
            reach = np.maximum(reach, span / depth if depth > 0 else 0.0)
        for j in range(d):
            x[j, ln] = reach * inside[j, ln] if ok else np.nan


def culprit(A, b, x, blame, pulling, d, width):
    """Of rows phase I found infeasible (``x (d, width)`` its end): the cone each leaves furthest into ``blame
    (width)`` (``argmax_m |y_mt| - y_m0``, NaN first, as numpy's ``argmax``), and :func:`pulling_possible` into
    ``pulling (width)``."""
    for ln in range(width):
        worst, who = -np.inf, 0
        for m in range(3):
            y0, y1, y2 = b[m, 0, ln], b[m, 1, ln], b[m, 2, ln]
            for j in range(d):
                y0 += A[m, 0, j, ln] * x[j, ln]
                y1 += A[m, 1, j, ln] * x[j, ln]
                y2 += A[m, 2, j, ln] * x[j, ln]
            over = np.sqrt(y1 * y1 + y2 * y2) - y0
            take = (over > worst) | (np.isnan(over) & np.logical_not(np.isnan(worst))) if m > 0 else True
            who = m if take else who
            worst = over if take else worst
        blame[ln] = who
    pulling_possible(A, pulling, d, width)


def pulling_possible(A, out, d, width):
    """Whether each row may be infeasible with unlimited friction too (the half-spaces ``n . f >= 0``), into
    ``out (width)``: it cannot where the squeezes reach every pattern of normal forces, ``|det N| > 1e-9 prod_m
    |N_m|`` of the 3 x 3 normal rows ``N_m = A_m0`` (``d = 3``; with more unknowns it may)."""
    for ln in range(width):
        det = (
            A[0, 0, 0, ln] * (A[1, 0, 1, ln] * A[2, 0, 2, ln] - A[1, 0, 2, ln] * A[2, 0, 1, ln])
            - A[0, 0, 1, ln] * (A[1, 0, 0, ln] * A[2, 0, 2, ln] - A[1, 0, 2, ln] * A[2, 0, 0, ln])
            + A[0, 0, 2, ln] * (A[1, 0, 0, ln] * A[2, 0, 1, ln] - A[1, 0, 1, ln] * A[2, 0, 0, ln])
        )
        size = 1.0
        for m in range(3):
            size *= np.sqrt(
                A[m, 0, 0, ln] * A[m, 0, 0, ln] + A[m, 0, 1, ln] * A[m, 0, 1, ln] + A[m, 0, 2, ln] * A[m, 0, 2, ln]
            )
        out[ln] = np.logical_not(np.abs(det) > 1e-9 * size) | (d != 3)


#: The lane-form functions, in the order their twins are made (callers may call any of them).
LANE_FORM = (_cross, contact_geometry, squeeze_directions, unit_normals, _spin, manipulating, twist_through, tangents)
LANE_FORM += (cone_frames, squeeze_map, cone_rows, plane_reduction, sector_rows, closure_test, own_sectors)
LANE_FORM += (internal_inside, start, culprit, pulling_possible)


def on_rows(name, *args):
    """:data:`LANE_FORM`'s function ``name`` by its numpy twin on arrays given rows first (each seen as lanes,
    :func:`lanes`; other arguments, the sizes and the width, as they are), numpy's warnings off: a twin
    computes both sides of its choices, and a row's division by zero is discarded with the side it is on.

    >>> e, sides = np.empty((1, 3, 3)), np.empty((1, 3))
    >>> on_rows("squeeze_directions", np.array([[[0, 0, 0], [2.0, 0, 0], [0, 2.0, 0]]]), e, sides, 1)
    >>> sides.round(4).tolist()
    [[2.8284, 2.0, 2.0]]
    """
    with np.errstate(all="ignore"):
        twins()[name](*(lanes(a) if isinstance(a, np.ndarray) else a for a in args))


@functools.cache
def twins():
    """``{name: numpy twin}`` of :data:`LANE_FORM` (made at the first use, not at import)."""
    from ._twin import twins as made  # ast and inspect: not at start-up

    return made(LANE_FORM)
