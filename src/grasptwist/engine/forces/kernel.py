r"""The grip compiled by numba, a whole row at a time (imported only through
:mod:`~grasptwist.engine.forces.compiled`, which loads it at the first grip).

:func:`grip_rows` does for each row what the numpy path does for the rows it solves by cones:
the geometry and ``G^+ w`` (:mod:`~grasptwist.engine.forces.grasp_map`), the cones and a start
inside them (:func:`~grasptwist.engine.forces.closure.internal_inside`), the interior-point
method of :mod:`~grasptwist.engine.forces.socp` step for step (Mehrotra's predictor-corrector
with Nesterov-Todd scaling, 0.99 of the way to the cones' edge, the same stopping rules, phase
I, dual polish and culprits; its scalar pieces are :mod:`~grasptwist.engine.forces.one`'s
functions, compiled), then the dual or the certificate and the figures.  The numpy path stays
the reference: ``tests/engine/test_forces.py`` holds the two to the same verdicts and totals to
``1e-9``.  A row of the method is ``A[m, k, j]`` (cone ``m``, component ``k``, unknown ``j``),
``b[m, k]``, ``c[j]``; ``d`` unknowns, ``K`` cones.  numpy's error model: a division by zero
is ``inf`` or NaN, which ends a row's iterations as a non-finite step does in numpy.
"""

from __future__ import annotations

import math
from itertools import accumulate

import numpy as np
from numba import njit

from . import one
from .closure import _PAIRS, _STRICT
from .grasp_map import GRIP_COLUMNS
from .socp import _EDGE, _ITERATIONS, _RESIDUAL, GAP, START_MARGIN

__all__ = ["grip_rows", "WIDTH"]

# no reference counting (numba's runtime) in the arithmetic: its atomic increments and decrements
# on every array passed or sliced were a fifth of a row's time; the workspaces are allocated by
# the two functions that need the runtime (_ALLOC)
_JIT = {"cache": True, "error_model": "numpy", "fastmath": {"arcp", "contract"}, "_nrt": False}
_ALLOC = {"cache": True}


# the scalar pieces are one.py's functions, compiled: the two paths share them line for line
_approach, _scaling, _w_inv, _w_mul = (njit(**_JIT)(f) for f in (one.approach, one.scaling, one.w_inv, one.w_mul))


@njit(**_JIT, inline="always")
def _spd_solve(H, g, d, out):
    """``H^-1 g`` by elimination without pivoting (``H`` symmetric positive definite, overwritten)."""
    for k in range(d):
        for i in range(k + 1, d):
            f = H[i, k] / H[k, k]
            for j in range(k + 1, d):
                H[i, j] -= f * H[k, j]
            g[i] -= f * g[k]
    for i in range(d - 1, -1, -1):
        v = g[i]
        for j in range(i + 1, d):
            v -= H[i, j] * out[j]
        out[i] = v / H[i, i]


@njit(**_JIT, inline="always")
def _apply(A, x, d, K, out):
    """``out_m = A_m x`` for the ``K`` cones."""
    for m in range(K):
        for k in range(3):
            t = 0.0
            for j in range(d):
                t += A[m, k, j] * x[j]
            out[m, k] = t


@njit(**_JIT, inline="always")
def _direction(A, L, V, beta, rhs, res, H, d, K, U, WU, g, Hw, dx, dy, dz):
    """``lambda o (W dz + W^-1 dy) = rhs``, ``dy = A dx``, ``sum_m A_m^T dz_m = res``: into ``dx, dy, dz``."""
    for m in range(K):
        l0, l1, l2 = L[m, 0], L[m, 1], L[m, 2]
        r0, r1, r2 = rhs[m, 0], rhs[m, 1], rhs[m, 2]
        u0 = (l0 * r0 - l1 * r1 - l2 * r2) / (l0 * l0 - l1 * l1 - l2 * l2)
        U[m, 0], U[m, 1], U[m, 2] = u0, (r1 - u0 * l1) / l0, (r2 - u0 * l2) / l0
        WU[m, 0], WU[m, 1], WU[m, 2] = _w_inv(V[m, 0], V[m, 1], V[m, 2], beta[m], U[m, 0], U[m, 1], U[m, 2])
    for j in range(d):
        t = res[j]
        for m in range(K):
            t -= A[m, 0, j] * WU[m, 0] + A[m, 1, j] * WU[m, 1] + A[m, 2, j] * WU[m, 2]
        g[j] = -t
        for i in range(d):
            Hw[j, i] = H[j, i]
    _spd_solve(Hw, g, d, dx)
    _apply(A, dx, d, K, dy)
    for m in range(K):
        q0, q1, q2 = _w_inv(V[m, 0], V[m, 1], V[m, 2], beta[m], dy[m, 0], dy[m, 1], dy[m, 2])
        dz[m, 0], dz[m, 1], dz[m, 2] = _w_inv(
            V[m, 0], V[m, 1], V[m, 2], beta[m], U[m, 0] - q0, U[m, 1] - q1, U[m, 2] - q2
        )


@njit(**_JIT, inline="always")
def _edge(y, z, dy, dz, ys, zs, K):
    """The largest step along ``(dy, dz)`` that keeps every ``y_m`` and ``z_m`` in its cone (``inf``: none):
    ``1 / max t`` of :func:`one.approach`'s rates (a NaN rate is no limit, as in ``socp._edge``)."""
    top = 0.0
    for m in range(K):
        t = _approach(y[m, 0], y[m, 1], y[m, 2], dy[m, 0], dy[m, 1], dy[m, 2], ys[m])
        if t > top:
            top = t
        t = _approach(z[m, 0], z[m, 1], z[m, 2], dz[m, 0], dz[m, 1], dz[m, 2], zs[m])
        if t > top:
            top = t
    return 1 / top if top > 0 else math.inf


@njit(**_JIT)
def _iterate(A, b, c, x, z, P, phase_one, d, K, ws):
    """``socp._iterate`` for one row (``phase_one``: its leaving rule, else phase II's); ``x``, ``z`` in place;
    ``ws``: :func:`_workspace` (indexed below ``d`` and ``K`` only)."""
    res, y, L, V, G, beta, scale, H, Hw, U, WU, rhs, square, g, dx, dy, dz, ys, zs = ws
    for it in range(_ITERATIONS):
        for j in range(d):
            t = c[j]
            for m in range(K):
                t -= A[m, 0, j] * z[m, 0] + A[m, 1, j] * z[m, 1] + A[m, 2, j] * z[m, 2]
            res[j] = t
        for m in range(K):
            for k in range(3):
                t = b[m, k]
                for j in range(d):
                    t += A[m, k, j] * x[j]
                y[m, k] = t
            w0, w1, w2, v0, v1, v2, bt, L[m, 0], L[m, 1], L[m, 2], ys[m], zs[m] = _scaling(
                y[m, 0], y[m, 1], y[m, 2], z[m, 0], z[m, 1], z[m, 2]
            )
            for j in range(d):
                G[m, j] = A[m, 0, j] * w0 - A[m, 1, j] * w1 - A[m, 2, j] * w2
            V[m, 0], V[m, 1], V[m, 2] = v0, v1, v2
            beta[m] = bt
            scale[m] = 1 / (bt * bt)
        top = -math.inf
        for i in range(d):
            for j in range(i + 1):
                h = 0.0
                for m in range(K):
                    h += (2 * G[m, i] * G[m, j] - P[m, i, j]) * scale[m]
                H[i, j] = h
                H[j, i] = h
            top = max(top, H[i, i])
        for i in range(d):
            H[i, i] += 1e-14 * top
        mu = 0.0
        for m in range(K):
            l0, l1, l2 = L[m, 0], L[m, 1], L[m, 2]
            square[m, 0], square[m, 1], square[m, 2] = l0 * l0 + l1 * l1 + l2 * l2, 2 * l0 * l1, 2 * l0 * l2
            rhs[m, 0], rhs[m, 1], rhs[m, 2] = -square[m, 0], -square[m, 1], -square[m, 2]
            mu += y[m, 0] * z[m, 0] + y[m, 1] * z[m, 1] + y[m, 2] * z[m, 2]
        mu /= K
        _direction(A, L, V, beta, rhs, res, H, d, K, U, WU, g, Hw, dx, dy, dz)
        step = min(1.0, _edge(y, z, dy, dz, ys, zs, K))
        mu_aff = 0.0
        for m in range(K):
            for k in range(3):
                mu_aff += (y[m, k] + step * dy[m, k]) * (z[m, k] + step * dz[m, k])
        sigma = min(max(mu_aff / K / mu, 0.0), 1.0) ** 3
        for m in range(K):
            p0, p1, p2 = _w_inv(V[m, 0], V[m, 1], V[m, 2], beta[m], dy[m, 0], dy[m, 1], dy[m, 2])
            q0, q1, q2 = _w_mul(V[m, 0], V[m, 1], V[m, 2], beta[m], dz[m, 0], dz[m, 1], dz[m, 2])
            rhs[m, 0] = -square[m, 0] - (p0 * q0 + p1 * q1 + p2 * q2) + sigma * mu
            rhs[m, 1] = -square[m, 1] - (p0 * q1 + q0 * p1)
            rhs[m, 2] = -square[m, 2] - (p0 * q2 + q0 * p2)
        _direction(A, L, V, beta, rhs, res, H, d, K, U, WU, g, Hw, dx, dy, dz)
        step = min(1.0, _EDGE * _edge(y, z, dy, dz, ys, zs, K))
        finite = math.isfinite(step)
        for j in range(d):
            finite = finite and math.isfinite(dx[j])
        for m in range(K):
            for k in range(3):
                finite = finite and math.isfinite(dz[m, k])
        if not finite:  # round-off at the cones' edge: the row stops where it is, still inside
            return it
        for j in range(d):
            x[j] += step * dx[j]
        gap = 0.0
        for m in range(K):
            for k in range(3):
                z[m, k] += step * dz[m, k]
                gap += (y[m, k] + step * dy[m, k]) * z[m, k]
        obj = 0.0
        big = 0.0
        for j in range(d):
            obj += c[j] * x[j]
            big = max(big, abs(res[j]))
        dual = obj - gap if big * (1 - step) <= _RESIDUAL else -math.inf
        closed = gap <= GAP * (1 + abs(obj))
        if phase_one:
            size = 1.0
            for j in range(d):
                size += abs(x[j])
            if x[d - 1] <= -START_MARGIN or dual > _RESIDUAL * size or (closed and dual > -math.inf):
                return it + 1
        elif closed and dual > -math.inf:
            return it + 1
    return _ITERATIONS


#: The most unknowns and cones a row has: phase I of collinear contacts' four internal forces.
_D, _K = 5, 4

# The kernel's rows: three squeezes, three cones (phase I: one more of each).  Passed to _iterate as
# constants, so that numba compiles it for these sizes (its loops unrolled): 7.6 -> 6.4 us a grasp.
_SQUEEZES, _CONES = 3, 3


@njit(**_ALLOC)
def _workspace():
    """The arrays :func:`_iterate` works in, allocated once per call of :func:`solve` (numba's
    allocations, not the arithmetic, were most of a row's time)."""
    return (
        np.empty(_D),
        np.empty((_K, 3)),
        np.empty((_K, 3)),
        np.empty((_K, 3)),
        np.empty((_K, _D)),
        np.empty(_K),
        np.empty(_K),
        np.empty((_D, _D)),
        np.empty((_D, _D)),
        np.empty((_K, 3)),
        np.empty((_K, 3)),
        np.empty((_K, 3)),
        np.empty((_K, 3)),
        np.empty(_D),
        np.empty(_D),
        np.empty((_K, 3)),
        np.empty((_K, 3)),
        np.empty(_K),
        np.empty(_K),
    )


@njit(**_JIT)
def _newton_matrices(A, d, K, P):
    for m in range(K):
        for i in range(d):
            for j in range(d):
                P[m, i, j] = A[m, 0, i] * A[m, 0, j] - A[m, 1, i] * A[m, 1, j] - A[m, 2, i] * A[m, 2, j]


@njit(**_ALLOC)
def _row_workspace():
    """The arrays of one row's phases (``wide``, ``bw``, ``cw``, ``xw``, ``zw``, ``P``, ``c``, ``x``, ``h``, ``dz``)."""
    return (
        np.empty((_K, 3, _D)),
        np.empty((_K, 3)),
        np.empty(_D),
        np.empty(_D),
        np.empty((_K, 3)),
        np.empty((_K, _D, _D)),
        np.empty(_D),
        np.empty(_D),
        np.empty((_D, _D)),
        np.empty((_K, 3)),
    )


@njit(**_JIT)
def _phase_one(A, b, rays, ws, rw):
    """``socp.phase_one`` for one row into ``rw``'s ``xw`` (``x`` and ``r`` last) and ``zw``; ``rays``: the cones
    with no friction limit (``b``'s tangential components taken as 0)."""
    K, d = A.shape[0], A.shape[2]
    wide, bw, c, x, z, P = rw[0], rw[1], rw[2], rw[3], rw[4], rw[5]
    over = -math.inf
    for m in range(K + 1):
        for k in range(3):
            bw[m, k] = b[m, k] if m < K and (k == 0 or not rays) else 0.0
            for j in range(d + 1):
                wide[m, k, j] = A[m, k, j] if m < K and j < d and (k == 0 or not rays) else 0.0
        wide[m, 0, d] = 1.0
        z[m, 0], z[m, 1], z[m, 2] = 0.25, 0.0, 0.0
        if m < K:
            over = max(over, math.hypot(bw[m, 1], bw[m, 2]) - bw[m, 0])
    bw[K, 0] = 1.0
    for j in range(d + 1):
        x[j] = 0.0
        c[j] = 0.0
    x[d] = max(over + 1, 0.0)
    c[d] = 1.0
    _newton_matrices(wide, _SQUEEZES + 1, _CONES + 1, P)
    _iterate(wide, bw, c, x, z, P, True, _SQUEEZES + 1, _CONES + 1, ws)
    return x[d]


@njit(**_JIT)
def _dual_polish(A, b, c, x, z, rw):
    """``grip._dual_polish`` for one row (``z`` in place)."""
    K, d = A.shape[0], A.shape[2]
    res, omega, h, dz, delta = rw[2], rw[1][:, 0], rw[8], rw[9], rw[3]
    for j in range(d):
        res[j] = c[j]
    for m in range(K):
        ny, nz = 0.0, 0.0
        for k in range(3):
            t = b[m, k]
            for j in range(d):
                t += A[m, k, j] * x[j]
                res[j] -= A[m, k, j] * z[m, k]
            ny += t * t
            nz += z[m, k] * z[m, k]
        omega[m] = math.sqrt(nz) / max(math.sqrt(ny), 1e-300)
    for i in range(d):
        for j in range(d):
            t = 0.0
            for m in range(K):
                for k in range(3):
                    t += omega[m] * A[m, k, i] * A[m, k, j]
            h[i, j] = t
        h[i, i] += 1e-300
    _spd_solve(h, res, d, delta)
    _apply(A, delta, d, K, dz)
    for m in range(K):
        for k in range(3):
            dz[m, k] *= omega[m]
            if not math.isfinite(dz[m, k]):
                return
    for m in range(K):
        for k in range(3):
            z[m, k] += dz[m, k]


@njit(**_JIT)
def _solve_row(A, b, inside, s, z, ws, rw):
    """``grip._solve`` for one row: ``s``, ``z`` filled (NaN ``s`` where it fails); returns ``(fail, blame)``."""
    K, d = A.shape[0], A.shape[2]
    c, x = rw[6], rw[7]
    for j in range(d):
        c[j] = 0.0
        for m in range(K):
            c[j] += A[m, 0, j]
    closing = True
    for j in range(d):
        closing = closing and not math.isnan(inside[j])
    r = -1.0
    if closing:
        reach = -math.inf
        for m in range(K):
            y0, y1, y2 = 0.0, 0.0, 0.0
            for j in range(d):
                y0 += A[m, 0, j] * inside[j]
                y1 += A[m, 1, j] * inside[j]
                y2 += A[m, 2, j] * inside[j]
            depth = y0 - math.sqrt(y1 * y1 + y2 * y2)
            reach = max(reach, (START_MARGIN + abs(b[m, 0]) + math.sqrt(b[m, 1] ** 2 + b[m, 2] ** 2)) / depth)
        for j in range(d):
            x[j] = reach * inside[j]
    else:
        r = _phase_one(A, b, False, ws, rw)
        for j in range(d):
            x[j] = rw[3][j]
        for m in range(K):
            for k in range(3):
                z[m, k] = rw[4][m, k]
    if not r < 0:
        worst, blame = -math.inf, 0
        for m in range(K):
            y0, y1, y2 = b[m, 0], b[m, 1], b[m, 2]
            for j in range(d):
                y0 += A[m, 0, j] * x[j]
                y1 += A[m, 1, j] * x[j]
                y2 += A[m, 2, j] * x[j]
            over = math.sqrt(y1 * y1 + y2 * y2) - y0
            if over > worst or (math.isnan(over) and not math.isnan(worst)):  # argmax: NaN wins, as numpy's
                worst, blame = over, m
        # pulling: infeasible with unlimited friction too, possible unless the squeezes reach every normal force
        maybe = True
        if d == 3:
            det = (
                A[0, 0, 0] * (A[1, 0, 1] * A[2, 0, 2] - A[1, 0, 2] * A[2, 0, 1])
                - A[0, 0, 1] * (A[1, 0, 0] * A[2, 0, 2] - A[1, 0, 2] * A[2, 0, 0])
                + A[0, 0, 2] * (A[1, 0, 0] * A[2, 0, 1] - A[1, 0, 1] * A[2, 0, 0])
            )
            scale = 1.0
            for m in range(3):
                scale *= math.sqrt(A[m, 0, 0] ** 2 + A[m, 0, 1] ** 2 + A[m, 0, 2] ** 2)
            maybe = not abs(det) > 1e-9 * scale
        if maybe and not _phase_one(A, b, True, ws, rw) < 0:
            blame = -1
        for j in range(d):
            s[j] = math.nan
        return True, blame
    for m in range(K):
        z[m, 0], z[m, 1], z[m, 2] = 1.0, 0.0, 0.0
    P = rw[5]
    _newton_matrices(A, _SQUEEZES, _CONES, P)
    _iterate(A, b, c, x, z, P, False, _SQUEEZES, _CONES, ws)
    _dual_polish(A, b, c, x, z, rw)
    for j in range(d):
        s[j] = x[j]
    return False, -1


# where each of grasp_map.GRIP_COLUMNS starts, and the row's width
_F, _FM, _S, _FN, _FT, _USED, _TOTAL, _COND, _DUAL, _GAP, _CERT, WIDTH = accumulate(
    (w for _, w in GRIP_COLUMNS), initial=0
)
_JJ, _KK = (1, 2, 0), (2, 0, 1)  # screws.J, screws.K: side i joins contacts J[i] and K[i]


@njit(**_JIT)
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(**_JIT)
def _twist(q, mv, t, g, d, out, sign):
    """``sign`` times ``grip._twist_through``: the twist whose field at the contacts is nearest ``d (3, 3)``."""
    v0 = (d[0, 0] + d[1, 0] + d[2, 0]) / 3
    v1 = (d[0, 1] + d[1, 1] + d[2, 1]) / 3
    v2 = (d[0, 2] + d[1, 2] + d[2, 2]) / 3
    x0, x1, x2 = 0.0, 0.0, 0.0
    for i in range(3):
        c0, c1, c2 = _cross(q[i, 0], q[i, 1], q[i, 2], d[i, 0], d[i, 1], d[i, 2])
        x0, x1, x2 = x0 + c0, x1 + c1, x2 + c2
    _omega(q, mv, t, x0, x1, x2, out)
    o0, o1, o2 = out[3], out[4], out[5]
    c0, c1, c2 = _cross(o0, o1, o2, g[0], g[1], g[2])
    out[0], out[1], out[2] = v0 - c0, v1 - c1, v2 - c2
    for k in range(6):
        out[k] *= sign


@njit(**_JIT)
def _omega(q, mv, t, x0, x1, x2, out):
    """``J^-1 x`` in closed form (``grasp_map._manipulating``) into ``out[3:]``."""
    s0, s1, s2 = 0.0, 0.0, 0.0
    for i in range(3):
        qx = q[i, 0] * x0 + q[i, 1] * x1 + q[i, 2] * x2
        s0, s1, s2 = s0 + q[i, 0] * qx, s1 + q[i, 1] * qx, s2 + q[i, 2] * qx
    mm = mv[0] * mv[0] + mv[1] * mv[1] + mv[2] * mv[2]
    mx = (mv[0] * x0 + mv[1] * x1 + mv[2] * x2) / t
    out[3], out[4], out[5] = (mv[0] * mx + 3 * s0) / mm, (mv[1] * mx + 3 * s1) / mm, (mv[2] * mx + 3 * s2) / mm


@njit(**_JIT)
def _internal_inside(p, unit, mv, e, limit, out, rows):
    """``closure.internal_inside`` for one row: a unit squeeze strictly inside every cone into ``out (3)``,
    or NaN.  The planar reduction (``closure._Plane``), the sectors of half-angle ``atan(limit_i)``
    (``closure._own_rows``) and the extreme rays of their cone of squeezes (``closure.closure_test``);
    ``rows (6, 3)``: a workspace."""
    ml = math.sqrt(mv[0] ** 2 + mv[1] ** 2 + mv[2] ** 2)
    n0, n1, n2 = mv[0] / ml, mv[1] / ml, mv[2] / ml
    x0, x1, x2 = p[1, 0] - p[0, 0], p[1, 1] - p[0, 1], p[1, 2] - p[0, 2]
    xl = math.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    x0, x1, x2 = x0 / xl, x1 / xl, x2 / xl
    y0, y1, y2 = _cross(n0, n1, n2, x0, x1, x2)
    good = True
    for i in range(3):
        un = unit[i, 0] * n0 + unit[i, 1] * n1 + unit[i, 2] * n2
        sin = abs(un)
        cos = math.sqrt(max(1 - sin * sin, 0.0))
        p0, p1, p2 = unit[i, 0] - un * n0, unit[i, 1] - un * n1, unit[i, 2] - un * n2
        a, c = p0 * x0 + p1 * x1 + p2 * x2, p0 * y0 + p1 * y1 + p2 * y2
        h = math.sqrt(a * a + c * c)
        m0, m1 = a / h, c / h
        # theta = atan(limit), phi = asin(sin) without the angles (five libm calls a contact were a
        # tenth of a row's set-up): sin(theta - phi) sin(theta + phi) = (sin t - sin p)(sin t + sin p)
        radius = math.hypot(1.0, limit[i])  # no overflow for a huge limit
        cos_theta = 1 / radius
        sin_theta = 1.0 if math.isinf(limit[i]) else limit[i] / radius
        sin_phi = min(sin, 1.0)
        good = good and sin_theta > sin_phi and cos > 0
        sin_beta = math.sqrt(max((sin_theta - sin_phi) * (sin_theta + sin_phi), 0.0)) / cos
        cos_beta = min(cos_theta / cos, 1.0)
        for edge in range(2):
            sign = -1.0 if edge == 0 else 1.0
            v0 = sin_beta * m0 + sign * cos_beta * -m1
            v1 = sin_beta * m1 + sign * cos_beta * m0
            length = 0.0
            for sq in range(3):
                # the squeeze sq's force on contact i, in the plane's (x, y): contact_matrices(e)
                fx = fy = 0.0
                if sq == _KK[i]:
                    fx, fy = (
                        e[sq, 0] * x0 + e[sq, 1] * x1 + e[sq, 2] * x2,
                        e[sq, 0] * y0 + e[sq, 1] * y1 + e[sq, 2] * y2,
                    )
                elif sq == _JJ[i]:
                    fx = -(e[sq, 0] * x0 + e[sq, 1] * x1 + e[sq, 2] * x2)
                    fy = -(e[sq, 0] * y0 + e[sq, 1] * y1 + e[sq, 2] * y2)
                rows[2 * i + edge, sq] = fx * v0 + fy * v1
                length += rows[2 * i + edge, sq] ** 2
            length = math.sqrt(length)
            for sq in range(3):
                rows[2 * i + edge, sq] /= length
    s0 = s1 = s2 = 0.0
    for pair in range(len(_PAIRS)):  # in closure_test's order
        a, c = _PAIRS[pair]
        c0, c1, c2 = _cross(rows[a, 0], rows[a, 1], rows[a, 2], rows[c, 0], rows[c, 1], rows[c, 2])
        length = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
        if not length > _STRICT:
            continue
        c0, c1, c2 = c0 / length, c1 / length, c2 / length
        above, below = True, True
        for k in range(6):
            t = rows[k, 0] * c0 + rows[k, 1] * c1 + rows[k, 2] * c2
            above = above and t >= -_STRICT
            below = below and t <= _STRICT
        sign = (1.0 if above else 0.0) - (1.0 if below else 0.0)
        s0, s1, s2 = s0 + c0 * sign, s1 + c1 * sign, s2 + c2 * sign
    length = math.sqrt(s0 * s0 + s1 * s1 + s2 * s2)
    s0, s1, s2 = s0 / length, s1 / length, s2 / length
    good = good and length > _STRICT
    for k in range(6):
        good = good and rows[k, 0] * s0 + rows[k, 1] * s1 + rows[k, 2] * s2 > _STRICT
    out[0], out[1], out[2] = (s0, s1, s2) if good else (math.nan, math.nan, math.nan)


@njit(**_ALLOC)
def grip_rows(p, n, limit, w, tol, out, codes):
    """The whole grip of the rows numpy's :class:`grip._Prepared` solves by cones (three distinct,
    non-collinear contacts, friction at each).

    ``out (n, WIDTH)``: the fields of :data:`grasp_map.GRIP_COLUMNS`; ``codes (n, 3)`` int8: status,
    culprit, plain.  ``plain = 0`` leaves a row to the numpy path: any other kind of row, a
    non-finite number (input, or an overflow on the way), a wrench on the edge of what the fingers
    exert.  ``limit (n, 3)`` is ``mu / safety``.
    """
    _grip_rows(p, n, limit, w, tol, out, codes, _workspace(), _row_workspace(), _grip_workspace())


@njit(**_ALLOC)
def _grip_workspace():
    """The arrays of one row's geometry, cones and answer (``M`` zero off its squeezes' entries)."""
    return (
        np.empty((3, 3)),
        np.empty(3),
        np.empty(3),
        np.empty((3, 3)),
        np.empty((3, 3)),
        np.empty((3, 3)),
        np.empty((3, 3, 3)),
        np.zeros((3, 3, 3)),
        np.empty((3, 3, 3)),
        np.empty((3, 3)),
        np.empty(3),
        np.empty((3, 3)),
        np.empty((3, 3)),
        np.empty(6),
        np.empty(3),
        np.empty((6, 3)),
    )


@njit(**_JIT)
def _grip_rows(p, n, limit, w, tol, out, codes, ws, rw, gw):
    """:func:`grip_rows` in the workspaces ``ws``, ``rw`` and ``gw`` (:func:`_grip_workspace`)."""
    q, mv, g, unit, e, fm, frame, M, A, b, s, z, d, lam, inside, corners = gw
    for r in range(p.shape[0]):
        o = out[r]
        codes[r, 0], codes[r, 1], codes[r, 2] = 0, -1, 0
        plain = True
        for i in range(3):
            for k in range(3):
                plain = plain and math.isfinite(p[r, i, k]) and math.isfinite(n[r, i, k])
            plain = plain and limit[r, i] > 0  # NaN and 0 (frictionless, mixed) to numpy
        for k in range(6):
            plain = plain and math.isfinite(w[r, k])
        if not plain:
            continue
        # geometry (grasp_map.geometry): centroid, spread, conditioning; degenerate rows to numpy
        for k in range(3):
            g[k] = (p[r, 0, k] + p[r, 1, k] + p[r, 2, k]) / 3
        t, size2 = 0.0, 0.0
        for i in range(3):
            q2 = 0.0
            for k in range(3):
                q[i, k] = p[r, i, k] - g[k]
                q2 += q[i, k] * q[i, k]
            t += q2
            size2 = max(size2, q2)
        mv[0], mv[1], mv[2] = _cross(
            p[r, 1, 0] - p[r, 0, 0],
            p[r, 1, 1] - p[r, 0, 1],
            p[r, 1, 2] - p[r, 0, 2],
            p[r, 2, 0] - p[r, 0, 0],
            p[r, 2, 1] - p[r, 0, 1],
            p[r, 2, 2] - p[r, 0, 2],
        )
        mm = mv[0] * mv[0] + mv[1] * mv[1] + mv[2] * mv[2]
        det = mm / 3
        small = 2 * det / (t + math.sqrt(max(t * t - 4 * det, 0.0)))
        conditioning = math.sqrt(2 * small / t)
        plain = t > 0 and conditioning > tol
        for i in range(3):
            a, c = _JJ[i], _KK[i]
            e0, e1, e2 = p[r, c, 0] - p[r, a, 0], p[r, c, 1] - p[r, a, 1], p[r, c, 2] - p[r, a, 2]
            side = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
            plain = plain and side > tol * math.sqrt(t)
            e[i, 0], e[i, 1], e[i, 2] = e0 / side, e1 / side, e2 / side
            length = math.sqrt(n[r, i, 0] ** 2 + n[r, i, 1] ** 2 + n[r, i, 2] ** 2)
            plain = plain and length > 0
            for k in range(3):
                unit[i, k] = n[r, i, k] / length
        if not plain:
            continue
        # G^+ w (grasp_map._manipulating): the twist (omega; F/3) about the centroid
        F0, F1, F2 = w[r, 0], w[r, 1], w[r, 2]
        c0, c1, c2 = _cross(g[0], g[1], g[2], F0, F1, F2)
        _omega(q, mv, t, w[r, 3] - c0, w[r, 4] - c1, w[r, 5] - c2, lam)
        scale = 0.0
        for i in range(3):
            c0, c1, c2 = _cross(lam[3], lam[4], lam[5], q[i, 0], q[i, 1], q[i, 2])
            fm[i, 0], fm[i, 1], fm[i, 2] = F0 / 3 + c0, F1 / 3 + c1, F2 / 3 + c2
            for k in range(3):
                o[_FM + 3 * i + k] = fm[i, k]
                scale = max(scale, abs(fm[i, k]))
                plain = plain and math.isfinite(fm[i, k])
        if not plain:  # overflow: nonfinite-result, said by the numpy path
            continue
        o[_COND] = conditioning
        for k in range(6):
            o[_CERT + k] = math.nan
        fail, blame = False, -1
        if scale == 0:  # no wrench: no force at all is the least
            for k in range(3):
                s[k] = 0.0
            for k in range(6):
                o[_DUAL + k] = 0.0
        else:
            # the cones (grasp_map.tangent_bases, grip._cones) and the squeezes' map (contact_matrices)
            for i in range(3):
                kappa = 0.0 if math.isinf(limit[r, i]) else 1 / limit[r, i]
                u0, u1, u2 = unit[i, 0], unit[i, 1], unit[i, 2]
                b0, b1, b2 = _cross(u0, u1, u2, 1.0, 0.0, 0.0) if abs(u0) < 0.9 else _cross(u0, u1, u2, 0.0, 1.0, 0.0)
                bl = math.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
                b0, b1, b2 = b0 / bl, b1 / bl, b2 / bl
                t0, t1, t2 = _cross(u0, u1, u2, b0, b1, b2)
                frame[i, 0, 0], frame[i, 0, 1], frame[i, 0, 2] = u0, u1, u2
                frame[i, 1, 0], frame[i, 1, 1], frame[i, 1, 2] = kappa * b0, kappa * b1, kappa * b2
                frame[i, 2, 0], frame[i, 2, 1], frame[i, 2, 2] = kappa * t0, kappa * t1, kappa * t2
                for k in range(3):
                    M[i, k, _KK[i]] = e[_KK[i], k]
                    M[i, k, _JJ[i]] = -e[_JJ[i], k]
                    M[i, k, i] = 0.0
            for i in range(3):
                for k in range(3):
                    b[i, k] = (
                        frame[i, k, 0] * (fm[i, 0] / scale)
                        + frame[i, k, 1] * (fm[i, 1] / scale)
                        + frame[i, k, 2] * (fm[i, 2] / scale)
                    )
                    for j in range(3):
                        A[i, k, j] = (
                            frame[i, k, 0] * M[i, 0, j] + frame[i, k, 1] * M[i, 1, j] + frame[i, k, 2] * M[i, 2, j]
                        )
            for i in range(3):
                for k in range(3):
                    z[i, k] = 0.0
            _internal_inside(p[r], unit, mv, e, limit[r], inside, corners)
            fail, blame = _solve_row(A, b, inside, s, z, ws, rw)
            # the multipliers as forces' duals; the dual twist through n_i - u_i, phase I's y through -u_i
            for i in range(3):
                for k in range(3):
                    d[i, k] = frame[i, 0, k] * z[i, 0] + frame[i, 1, k] * z[i, 1] + frame[i, 2, k] * z[i, 2]
            if fail:
                _twist(q, mv, t, g, d, lam, -1.0)
                yw, yy, ww = 0.0, 0.0, 0.0
                for k in range(6):
                    yw += lam[k] * w[r, k]
                    yy += lam[k] * lam[k]
                    ww += w[r, k] * w[r, k]
                if not yw > 1e-8 * math.sqrt(yy) * math.sqrt(ww):  # grip._EDGE_OF_HOLD: facial reduction in numpy
                    continue
                length = math.sqrt(
                    lam[0] ** 2 + lam[1] ** 2 + lam[2] ** 2 + size2 * (lam[3] ** 2 + lam[4] ** 2 + lam[5] ** 2)
                )
                for k in range(6):
                    o[_CERT + k] = lam[k] / length
                    o[_DUAL + k] = math.nan
            else:
                for i in range(3):
                    for k in range(3):
                        d[i, k] = unit[i, k] - d[i, k]
                _twist(q, mv, t, g, d, lam, 1.0)
                for k in range(6):
                    o[_DUAL + k] = lam[k]
        codes[r, 0], codes[r, 1] = (20, blame) if fail else (0, -1)
        # the forces and their figures (grip._Prepared.solve, grasp_map.checked_grip)
        top, total, finite = 0.0, 0.0, True
        for i in range(3):
            for k in range(3):
                f = fm[i, k] + scale * (M[i, k, 0] * s[0] + M[i, k, 1] * s[1] + M[i, k, 2] * s[2]) if scale else 0.0
                o[_F + 3 * i + k] = math.nan if fail else f
                top = max(top, abs(f))
            o[_S + i] = math.nan if fail else scale * s[i]
        for i in range(3):
            fn = 0.0
            for k in range(3):
                fn += o[_F + 3 * i + k] * unit[i, k]
            ft2 = 0.0
            for k in range(3):
                tk = o[_F + 3 * i + k] - fn * unit[i, k]
                ft2 += tk * tk
            ft = math.sqrt(ft2)
            o[_FN + i], o[_FT + i] = fn, ft
            o[_USED + i] = 0.0 if not fail and ft <= 1e-12 * top else ft / fn
            total += fn
            finite = finite and math.isfinite(fn) and math.isfinite(ft) and math.isfinite(o[_USED + i])
        o[_TOTAL] = total
        finite = finite and math.isfinite(total)
        gap = total
        for k in range(6):
            gap -= w[r, k] * o[_DUAL + k]
            finite = finite and math.isfinite(o[_DUAL + k])
        o[_GAP] = gap
        codes[r, 2] = 1 if fail or (finite and math.isfinite(gap)) else 0
