r"""The interior-point method of :mod:`~grasptwist.engine.forces.socp` for one row, in Python floats.

The iteration is :mod:`~grasptwist.engine.forces.ipm`'s lane form, the source numba compiles and
numpy runs batched, through its *float twin* (:func:`_twin.floats`: one lane, nested lists of
floats, ``math`` for numpy's scalar calls).  For one grasp numpy's cost per call (a microsecond
or more, on arrays of three numbers) is all there is: an iteration of the batched twin makes
some 700 numpy calls, where the float twin does a few hundred float operations.  This module is
its driver (the start points, each phase's stopping rules, the cap) and the pieces that are
its own: the facial reduction's closed form :func:`least_on_line` and :func:`dual_polish`, which
:mod:`~grasptwist.engine.forces.kernel` compiles too.  ``tests/engine/test_ipm.py`` holds the
float twin's iterates to the numpy twin's, ``tests/engine/test_forces.py`` this driver to the
batched solver on random rows (the verdicts, and the optimum to ``1e-9``).

A row is ``A[m][k][j]`` (cone ``m``, component ``k``, unknown ``j``), ``b[m][k]``,
``c[j]``; the unknowns ``x[j]`` and the cones' multipliers ``z[m][k]`` are lists updated in place.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from . import ipm
from .ipm import ITERATIONS

__all__ = ["iterate", "phase_one", "minimise", "newton_matrices", "solve", "least_on_line", "dual_polish"]


@functools.cache
def _twin():
    """:mod:`~grasptwist.engine.forces.ipm`'s float twins (made at the first solve, not at import)."""
    from ._twin import floats  # ast and inspect: not at start-up

    return floats(ipm.LANE_FORM)


@functools.cache
def _set_up_twin():
    """:mod:`~grasptwist.engine.forces.set_up`'s float twins (made at the first one-grasp grip)."""
    from . import set_up
    from ._twin import floats

    return floats(set_up.LANE_FORM)


def least_on_line(a, b, count):
    """The least ``c t`` over the line ``a_m t + b_m`` in the cones ``Q^3`` (``m < count``), ``c = sum_m a_m0``:
    ``(t, m, coef)``, the cone ``m`` that ends the line there and its multiplier ``coef J (a_m t + b_m)``
    (the only one: ``sum_m a_m^T z_m = c``), or ``(nan, -1, nan)``: no least, or not sharply.

    Each cone holds on an interval of ``t``: ``g(t) = (a t + b)^T J (a t + b) = alpha t^2 + 2 beta t +
    gamma >= 0`` with ``a_0 t + b_0 >= 0``, between the roots of ``g`` (``alpha < 0``), beyond the one on
    the cone's side (``alpha > 0``: ``a`` inside the cone or its opposite), or a half-line (``alpha = 0``).
    Where ``c = 0`` every feasible ``t`` is least: the interval's analytic centre (the maximum of
    ``sum_m log g_m(t)``, where the interior-point method's central path goes) and no multiplier.
    The facial reduction's last step (``grip._on_the_edge``), in closed form: the same source as
    Python floats and, compiled, in :mod:`~grasptwist.engine.forces.kernel`.  ``a, b`` are ``(count, 3)``
    (lists, or arrays: indexed ``a[m][k]``).

    >>> least_on_line([[0.0, 1.0, 0.0]], [[1.0, 0.0, 0.0]], 1)  # |t| <= 1 and c = 0: the centre
    (0.0, 0, 0.0)
    >>> least_on_line([[1.0, 0.0, 0.0], [1.0, 0.5, 0.0]], [[0.0, 0.0, 0.0], [0.0, -1.0, 0.0]], 2)  # t >= 2 / 3
    (0.6666666666666666, 1, 2.0)
    """
    lo, hi, low, high, c = -math.inf, math.inf, -1, -1, 0.0
    for m in range(count):
        a0, a1, a2, b0, b1, b2 = a[m][0], a[m][1], a[m][2], b[m][0], b[m][1], b[m][2]
        c += a0
        alpha, beta, gamma = a0 * a0 - a1 * a1 - a2 * a2, a0 * b0 - a1 * b1 - a2 * b2, b0 * b0 - b1 * b1 - b2 * b2
        disc = beta * beta - alpha * gamma
        start, end = -math.inf, math.inf
        if alpha == 0:  # a on the cone's edge: g is linear
            if beta > 0:
                start = -gamma / (2 * beta)
            elif beta < 0:
                end = -gamma / (2 * beta)
            elif not (gamma >= 0 and b0 >= 0):
                start, end = math.inf, -math.inf
        elif disc < 0:
            if alpha < 0:
                start, end = math.inf, -math.inf
        else:
            far = -(beta + math.copysign(math.sqrt(disc), beta))  # roots far / alpha, gamma / far: no cancellation
            t1, t2 = (far / alpha, gamma / far) if far != 0 else (0.0, 0.0)
            t1, t2 = min(t1, t2), max(t1, t2)
            if alpha > 0 and a0 > 0:
                start = t2
            elif alpha > 0:
                end = t1
            elif a0 * (t1 + t2) / 2 + b0 >= 0:
                start, end = t1, t2
            else:
                start, end = math.inf, -math.inf
        if start > lo:
            lo, low = start, m
        if end < hi:
            hi, high = end, m
    t, m = (lo, low) if c > 0 else (hi, high)
    if c == 0 and lo < hi and math.isfinite(lo) and math.isfinite(hi):
        # the total is the same all along: the analytic centre, where the central path goes, by bisection on
        # the derivative of sum_m log g_m(t), which falls (sqrt(g) is concave on the cone)
        for _ in range(200):
            t = (lo + hi) / 2
            if not lo < t < hi:
                break
            slope = 0.0
            for m in range(count):
                y0, y1, y2 = a[m][0] * t + b[m][0], a[m][1] * t + b[m][1], a[m][2] * t + b[m][2]
                slope += (a[m][0] * y0 - a[m][1] * y1 - a[m][2] * y2) / (y0 * y0 - y1 * y1 - y2 * y2)
            if slope == 0:
                break
            lo, hi = (t, hi) if slope > 0 else (lo, t)
        return (lo + hi) / 2, 0, 0.0
    if c == 0 or not lo <= hi or not math.isfinite(t):
        return math.nan, -1, math.nan
    y0 = a[m][0] * t + b[m][0]
    y1 = a[m][1] * t + b[m][1]
    y2 = a[m][2] * t + b[m][2]
    coef = c / (a[m][0] * y0 - a[m][1] * y1 - a[m][2] * y2)
    if not (coef > 0 and math.isfinite(coef)):
        return math.nan, -1, math.nan
    return t, m, coef


def newton_matrices(A):
    """``P_m[i][j] = A_m[:, i]^T J A_m[:, j]`` per cone: the part of the Newton matrix that stays
    (:func:`ipm.newton_part`'s float twin)."""
    K, k, d = len(A), len(A[0]), len(A[0][0])
    P = [[[0.0] * d for _ in range(d)] for _ in range(K)]
    _twin()["newton_part"](A, P, d, K, k, 1)
    return P


def iterate(A, b, c, x, z, P, phase):
    """:func:`socp._iterate` for one row: :func:`ipm.step`'s float twin moves ``x`` and ``z`` (lists, in place)
    until the row is done (phase I's rules where ``phase``) or the cap.  A division by zero or the root of a
    negative number (round-off at the cones' edge, NaN in numpy) stops the row where it is, as the batched
    method's step that is not finite does."""
    from ._twin import float_workspace

    K, k, d = len(A), len(A[0]), len(x)
    step, work, done = _twin()["step"], float_workspace(ipm.workspace(d, K, k, 1)), [False]
    for _ in range(ITERATIONS):
        try:
            step(A, b, c, x, z, P, phase, work, done, d, K, k, 1)
        except (ValueError, ZeroDivisionError, OverflowError):
            return
        if done[0]:
            return


def phase_one(A, b):
    """:func:`socp.phase_one` for one row: ``(x, r, z)`` (``z`` of the row's cones)."""
    K, k, d = len(A), len(A[0]), len(A[0][0])
    wide = [[[0.0] * (d + 1) for _ in range(k)] for _ in range(K + 1)]
    bw, z = [[0.0] * k for _ in range(K + 1)], [[0.0] * k for _ in range(K + 1)]
    c, x = [0.0] * (d + 1), [0.0] * (d + 1)
    _twin()["widened"](A, b, wide, bw, c, x, z, d, K, k, 1)
    iterate(wide, bw, c, x, z, newton_matrices(wide), True)
    return x[:d], x[d], z[: len(A)]


def minimise(A, b, c, x, P):
    """:func:`socp.minimise` for one row from the strictly feasible ``x``: ``(x, z)``; ``P`` of :func:`newton_matrices`."""
    z = [[1.0, 0.0, 0.0] for _ in A]
    x = list(x)
    iterate(A, b, c, x, z, P, False)
    return x, z


def dual_polish(A, b, c, x, z, omega, h, dz):
    """:func:`socp.dual_polish` for one row: ``z (K, k)`` moved in place to ``sum_m A_m^T z_m = c`` again.

    ``A (K, k, d)``, ``b (K, k)``, ``c (d)``, ``x (d)``; workspaces ``omega (K)``, ``h (d, d + 1)``
    (the matrix, then the right-hand side), ``dz (K, k)``.  Elimination without pivoting; a row
    whose correction is not finite (every cone idle) is left as it is.  Arrays indexed
    element by element: :mod:`~grasptwist.engine.forces.kernel` compiles this same function (for
    the grip's rows, ``k = 3``, and for :func:`socp.dual_polish`'s of any cone), and :func:`solve`
    runs it as Python.
    """
    K, k, d = A.shape
    for j in range(d):
        h[j, d] = c[j]
    for m in range(K):
        ny, nz = 0.0, 0.0
        for q in range(k):
            t = b[m, q]
            for j in range(d):
                t += A[m, q, j] * x[j]
                h[j, d] -= A[m, q, j] * z[m, q]
            ny += t * t
            nz += z[m, q] * z[m, q]
        omega[m] = math.sqrt(nz) / max(math.sqrt(ny), 1e-300)
    for i in range(d):
        for j in range(d):
            t = 0.0
            for m in range(K):
                for q in range(k):
                    t += omega[m] * A[m, q, i] * A[m, q, j]
            h[i, j] = t
        h[i, i] += 1e-300
    for q in range(d):
        for i in range(q + 1, d):
            f = h[i, q] / h[q, q]
            for j in range(q + 1, d + 1):
                h[i, j] -= f * h[q, j]
    for i in range(d - 1, -1, -1):
        v = h[i, d]
        for j in range(i + 1, d):
            v -= h[i, j] * h[j, d]
        h[i, d] = v / h[i, i]
    for m in range(K):
        for q in range(k):
            t = 0.0
            for j in range(d):
                t += A[m, q, j] * h[j, d]
            dz[m, q] = t * omega[m]
            if not math.isfinite(dz[m, q]):
                return
    for m in range(K):
        for q in range(k):
            z[m, q] += dz[m, q]


def solve(A, b, c, P, inside, rays):
    """``grip._solve`` for one row of lists: ``(s, z, fail, blame)``.

    ``inside``: the unknowns of an internal force strictly inside every cone, or None; ``rays``: the row's
    ``A`` with unlimited friction (the cones' first rows), for the pulling test.  The start and the culprit
    are :mod:`~grasptwist.engine.forces.set_up`'s, through their float twins.
    """
    d = len(c)
    lanes = _set_up_twin()
    x, r, z = [0.0] * d, -1.0, None
    if inside is not None:
        lanes["start"](A, b, inside, x, d, 1)
    if inside is None or math.isnan(x[0]):  # no squeeze inside, or one on a cone's edge: phase I's start
        x, r, z = phase_one(A, b)
    if not r < 0:
        blame, pulling = [0], [False]
        lanes["culprit"](A, b, x, blame, pulling, d, 1)
        if pulling[0] and phase_one(rays, [[bm[0], 0.0, 0.0] for bm in b])[1] >= 0:
            blame[0] = -1
        return [math.nan] * d, z, True, blame[0]
    s, z = minimise(A, b, c, x, P)
    A, b, x, z = np.array(A), np.array(b), np.array(s), np.array(z)
    K, d = A.shape[0], A.shape[2]
    with np.errstate(all="ignore"):  # a zero pivot: the correction is not finite, z stays
        dual_polish(A, b, np.array(c), x, z, np.empty(K), np.empty((d, d + 1)), np.empty((K, 3)))
    return s, z.tolist(), False, -1
