r"""The interior-point method of :mod:`~grasptwist.engine.forces.socp` for one row, in Python floats.

The batched method's iteration is written once (:mod:`~grasptwist.engine.forces.ipm`, run by numpy
and compiled by numba); this copy for Q3 rows stays because one row through that source is slow:
0.75 ms a step as Python on one lane and 0.97 ms through the numpy twin, where this whole solve takes
about 2 ms.

For one grasp numpy's cost per call (a microsecond or more, on arrays of three numbers)
is all there is: an iteration of the batched method makes some 700 numpy calls.  This is
the same method, step for step (Mehrotra's predictor-corrector with Nesterov-Todd
scaling, 0.99 of the way to the cones' edge, the same stopping rules), on lists of
floats: a few hundred multiplications an iteration.  ``tests/engine/test_forces.py`` holds it to
the batched solver on random rows (the verdicts, and the optimum to ``1e-9``).

A row is ``A[m][k][j]`` (cone ``m``, component ``k``, unknown ``j``), ``b[m][k]``,
``c[j]``; the unknowns ``x[j]`` and the cones' multipliers ``z[m][k]`` are lists updated in place.
"""

from __future__ import annotations

import math

import numpy as np

from .ipm import EDGE as _EDGE
from .ipm import GAP, START_MARGIN
from .ipm import ITERATIONS as _ITERATIONS
from .ipm import RESIDUAL as _RESIDUAL

__all__ = [
    "phase_one",
    "minimise",
    "newton_matrices",
    "solve",
    "approach",
    "scaling",
    "w_inv",
    "w_mul",
    "least_on_line",
]


def approach(x0, x1, x2, d0, d1, d2, s):
    """How fast ``x + alpha d`` nears the cone's edge: ``t`` with the largest ``alpha`` in the cone
    ``1 / t`` where ``t > 0`` (none otherwise), as :func:`socp._edge`; ``s = sqrt(x0^2 - x1^2 - x2^2)``,
    which :func:`scaling` has computed already.  A step's length is ``1 / max t`` over its cones: one
    division, not one a cone.
    """
    x0, x1, x2 = x0 / s, x1 / s, x2 / s
    d0, d1, d2 = d0 / s, d1 / s, d2 / s
    rho0 = x0 * d0 - x1 * d1 - x2 * d2
    f = (rho0 + d0) / (x0 + 1)
    e1, e2 = d1 - f * x1, d2 - f * x2
    return math.sqrt(e1 * e1 + e2 * e2) - rho0


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


def _edge(x, d):
    t = approach(x[0], x[1], x[2], d[0], d[1], d[2], math.sqrt(x[0] * x[0] - x[1] * x[1] - x[2] * x[2]))
    return 1 / t if t > 0 else math.inf


def scaling(y0, y1, y2, z0, z1, z2):
    """Nesterov-Todd scaling of one cone (``W z = W^-1 y = lambda``, ``W = beta (2 v v^T - J)``):
    ``(w0, w1, w2, v0, v1, v2, beta, lambda0, lambda1, lambda2, ys, zs)`` (``w`` the scaling point,
    ``ys = sqrt(y^T J y)`` and ``zs`` the cones' own norms of ``y`` and ``z``, for :func:`approach`).
    """
    ys = math.sqrt(y0 * y0 - y1 * y1 - y2 * y2)
    zs = math.sqrt(z0 * z0 - z1 * z1 - z2 * z2)
    twice = 2 * math.sqrt((1 + (y0 * z0 + y1 * z1 + y2 * z2) / (ys * zs)) / 2)
    w0, w1, w2 = (y0 / ys + z0 / zs) / twice, (y1 / ys - z1 / zs) / twice, (y2 / ys - z2 / zs) / twice
    r = math.sqrt(2 * (w0 + 1))
    v0, v1, v2 = (w0 + 1) / r, w1 / r, w2 / r
    beta = math.sqrt(ys / zs)
    vz = 2 * (v0 * z0 + v1 * z1 + v2 * z2)
    return w0, w1, w2, v0, v1, v2, beta, beta * (v0 * vz - z0), beta * (v1 * vz + z1), beta * (v2 * vz + z2), ys, zs


def w_inv(v0, v1, v2, beta, u0, u1, u2):
    """``W^-1 u`` (plain floats)."""
    t = 2 * (v0 * u0 - v1 * u1 - v2 * u2)
    return (t * v0 - u0) / beta, (u1 - t * v1) / beta, (u2 - t * v2) / beta


def w_mul(v0, v1, v2, beta, u0, u1, u2):
    """``W u`` (plain floats)."""
    t = 2 * (v0 * u0 + v1 * u1 + v2 * u2)
    return beta * (t * v0 - u0), beta * (t * v1 + u1), beta * (t * v2 + u2)


def newton_matrices(A):
    """``P_m[i][j] = A_m[:, i]^T J A_m[:, j]`` per cone: the part of the Newton matrix that stays."""
    d = len(A[0][0])
    return [
        [[a[0][i] * a[0][j] - a[1][i] * a[1][j] - a[2][i] * a[2][j] for j in range(d)] for i in range(d)] for a in A
    ]


def _solve(h, g):
    """``h^-1 g`` by elimination without pivoting (``h`` symmetric positive definite; copied)."""
    d = len(g)
    if d == 3:  # the grip's squeezes: the same elimination, written out
        (h00, h01, h02), (h10, h11, h12), (h20, h21, h22) = h
        g0, g1, g2 = g
        f1, f2 = h10 / h00, h20 / h00
        h11, h12, g1 = h11 - f1 * h01, h12 - f1 * h02, g1 - f1 * g0
        h21, h22, g2 = h21 - f2 * h01, h22 - f2 * h02, g2 - f2 * g0
        f = h21 / h11
        h22, g2 = h22 - f * h12, g2 - f * g1
        x2 = g2 / h22
        x1 = (g1 - h12 * x2) / h11
        return [(g0 - h01 * x1 - h02 * x2) / h00, x1, x2]
    h = [row[:] for row in h]
    g = g[:]
    for k in range(d):
        for i in range(k + 1, d):
            f = h[i][k] / h[k][k]
            for j in range(k + 1, d):
                h[i][j] -= f * h[k][j]
            g[i] -= f * g[k]
    x = [0.0] * d
    for i in reversed(range(d)):
        v = g[i]
        for j in range(i + 1, d):
            v -= h[i][j] * x[j]
        x[i] = v / h[i][i]
    return x


def _iterate(A, b, c, x, z, P, leave):
    """:func:`socp._iterate` for one row; ``leave(x, closed, dual)`` ends it.  Returns False when a step
    was not finite (the row stops where it is, as the batched method's does)."""
    AT = [[tuple(a[k][j] for k in range(3)) for j in range(len(x))] for a in A]  # columns: A_m[:, j]
    for _ in range(_ITERATIONS):
        try:
            done = _step(AT, b, c, x, z, P, leave)
        except (ValueError, ZeroDivisionError, OverflowError):  # round-off at the cones' edge, as NaN is in numpy
            done = None
        if done is None:
            return False
        if done:
            return True
    return True


def _times(AT, b, x):
    """``A_m x + b_m`` per cone (``b`` None: ``A_m x``)."""
    out = []
    for m, cols in enumerate(AT):
        r0, r1, r2 = (0.0, 0.0, 0.0) if b is None else b[m]
        for (a0, a1, a2), xj in zip(cols, x):
            r0 += a0 * xj
            r1 += a1 * xj
            r2 += a2 * xj
        out.append((r0, r1, r2))
    return out


def _transposed(AT, u, first):
    """``first - sum_m A_m^T u_m``."""
    out = list(first)
    for cols, (u0, u1, u2) in zip(AT, u):
        for j, (a0, a1, a2) in enumerate(cols):
            out[j] -= a0 * u0 + a1 * u1 + a2 * u2
    return out


def _w_inv(v, beta, u):
    return w_inv(v[0], v[1], v[2], beta, u[0], u[1], u[2])


def _w_mul(v, beta, u):
    return w_mul(v[0], v[1], v[2], beta, u[0], u[1], u[2])


def _step(AT, b, c, x, z, P, leave):
    """One iteration of :func:`_iterate`: True when ``leave`` says so, None when the step is not finite."""
    K, d = len(AT), len(x)
    res = _transposed(AT, z, c)
    y = _times(AT, b, x)
    V, B, L, G = [], [], [], []
    for ym, zm, cols in zip(y, z, AT):
        w0, w1, w2, v0, v1, v2, beta, l0, l1, l2, _, _ = scaling(*ym, *zm)
        L.append((l0, l1, l2))
        G.append([a0 * w0 - a1 * w1 - a2 * w2 for a0, a1, a2 in cols])
        V.append((v0, v1, v2))
        B.append(1 / (beta * beta))
    H = [[0.0] * d for _ in range(d)]
    for i in range(d):
        for j in range(i + 1):
            h = 0.0
            for g, p, scale in zip(G, P, B):
                h += (2 * g[i] * g[j] - p[i][j]) * scale
            H[i][j] = H[j][i] = h
    ridge = 1e-14 * max(H[i][i] for i in range(d))
    for i in range(d):
        H[i][i] += ridge
    B = [1 / math.sqrt(scale) for scale in B]

    def direction(rhs):
        U, WU = [], []
        for (l0, l1, l2), (r0, r1, r2), v, beta in zip(L, rhs, V, B):
            u0 = (l0 * r0 - l1 * r1 - l2 * r2) / (l0 * l0 - l1 * l1 - l2 * l2)
            u = (u0, (r1 - u0 * l1) / l0, (r2 - u0 * l2) / l0)
            U.append(u)
            WU.append(_w_inv(v, beta, u))
        dx = _solve(H, [-g for g in _transposed(AT, WU, res)])
        dy = _times(AT, None, dx)
        dz = []
        for u, q, v, beta in zip(U, dy, V, B):
            q = _w_inv(v, beta, q)
            dz.append(_w_inv(v, beta, (u[0] - q[0], u[1] - q[1], u[2] - q[2])))
        return dx, dy, dz

    square = [(q0 * q0 + q1 * q1 + q2 * q2, 2 * q0 * q1, 2 * q0 * q2) for q0, q1, q2 in L]
    mu = sum(ym[0] * zm[0] + ym[1] * zm[1] + ym[2] * zm[2] for ym, zm in zip(y, z)) / K
    dx, dy, dz = direction([(-s0, -s1, -s2) for s0, s1, s2 in square])
    step = min(1.0, *(_edge(ym, dm) for ym, dm in zip(y, dy)), *(_edge(zm, dm) for zm, dm in zip(z, dz)))
    mu_aff = 0.0
    for ym, zm, dym, dzm in zip(y, z, dy, dz):
        for k in range(3):
            mu_aff += (ym[k] + step * dym[k]) * (zm[k] + step * dzm[k])
    sigma = min(max(mu_aff / K / mu, 0.0), 1.0) ** 3
    rhs = []
    for dym, dzm, (s0, s1, s2), v, beta in zip(dy, dz, square, V, B):
        p, q = _w_inv(v, beta, dym), _w_mul(v, beta, dzm)
        rhs.append(
            (
                -s0 - (p[0] * q[0] + p[1] * q[1] + p[2] * q[2]) + sigma * mu,
                -s1 - (p[0] * q[1] + q[0] * p[1]),
                -s2 - (p[0] * q[2] + q[0] * p[2]),
            )
        )
    dx, dy, dz = direction(rhs)
    step = min(1.0, _EDGE * min(*(_edge(ym, dm) for ym, dm in zip(y, dy)), *(_edge(zm, dm) for zm, dm in zip(z, dz))))
    if not (math.isfinite(step) and all(map(math.isfinite, dx)) and all(math.isfinite(v) for t in dz for v in t)):
        return None
    for j in range(d):
        x[j] += step * dx[j]
    gap = 0.0
    for m in range(K):
        zm = z[m] = [z[m][k] + step * dz[m][k] for k in range(3)]
        ym, dym = y[m], dy[m]
        gap += (ym[0] + step * dym[0]) * zm[0] + (ym[1] + step * dym[1]) * zm[1] + (ym[2] + step * dym[2]) * zm[2]
    obj = sum(cj * xj for cj, xj in zip(c, x))
    feasible = max(abs(r) for r in res) * (1 - step) <= _RESIDUAL
    return leave(x, gap <= GAP * (1 + abs(obj)), obj - gap if feasible else -math.inf)


def phase_one(A, b):
    """:func:`socp.phase_one` for one row: ``(x, r, z)`` (``z`` of the row's cones)."""
    d = len(A[0][0])
    wide = [[row[:] + [1.0 if k == 0 else 0.0] for k, row in enumerate(a)] for a in A]
    wide.append([[0.0] * d + [1.0], [0.0] * (d + 1), [0.0] * (d + 1)])
    bw = [list(bm) for bm in b] + [[1.0, 0.0, 0.0]]
    over = max(math.hypot(bm[1], bm[2]) - bm[0] for bm in b)
    x = [0.0] * d + [max(over + 1, 0.0)]
    z = [[0.25, 0.0, 0.0] for _ in range(len(A) + 1)]
    c = [0.0] * d + [1.0]

    def leave(x, closed, dual):
        return x[d] <= -START_MARGIN or dual > _RESIDUAL * (1 + sum(abs(v) for v in x)) or (closed and dual > -math.inf)

    _iterate(wide, bw, c, x, z, newton_matrices(wide), leave)
    return x[:d], x[d], z[: len(A)]


def minimise(A, b, c, x, P):
    """:func:`socp.minimise` for one row from the strictly feasible ``x``: ``(x, z)``; ``P`` of :func:`newton_matrices`."""
    z = [[1.0, 0.0, 0.0] for _ in A]
    x = list(x)

    def leave(x, closed, dual):
        return closed and dual > -math.inf

    _iterate(A, b, c, x, z, P, leave)
    return x, z


def _cone_value(a, bm, x):
    return [bm[k] + sum(a[k][j] * x[j] for j in range(len(x))) for k in range(3)]


def dual_polish(A, b, c, x, z, omega, h, dz):
    """:func:`socp.dual_polish` for one row: ``z (K, 3)`` moved in place to ``sum_m A_m^T z_m = c`` again.

    ``A (K, 3, d)``, ``b (K, 3)``, ``c (d)``, ``x (d)``; workspaces ``omega (K)``, ``h (d, d + 1)``
    (the matrix, then the right-hand side), ``dz (K, 3)``.  Elimination without pivoting; a row
    whose correction is not finite (every cone idle) is left as it is.  Arrays indexed
    element by element: :mod:`~grasptwist.engine.forces.kernel` compiles this same function,
    and :func:`solve` runs it as Python.
    """
    K, d = A.shape[0], A.shape[2]
    for j in range(d):
        h[j, d] = c[j]
    for m in range(K):
        ny, nz = 0.0, 0.0
        for k in range(3):
            t = b[m, k]
            for j in range(d):
                t += A[m, k, j] * x[j]
                h[j, d] -= A[m, k, j] * z[m, k]
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
    for k in range(d):
        for i in range(k + 1, d):
            f = h[i, k] / h[k, k]
            for j in range(k + 1, d + 1):
                h[i, j] -= f * h[k, j]
    for i in range(d - 1, -1, -1):
        v = h[i, d]
        for j in range(i + 1, d):
            v -= h[i, j] * h[j, d]
        h[i, d] = v / h[i, i]
    for m in range(K):
        for k in range(3):
            t = 0.0
            for j in range(d):
                t += A[m, k, j] * h[j, d]
            dz[m, k] = t * omega[m]
            if not math.isfinite(dz[m, k]):
                return
    for m in range(K):
        for k in range(3):
            z[m, k] += dz[m, k]


def solve(A, b, c, P, inside, normal_det, rays):
    """``grip._solve`` for one row of lists: ``(s, z, fail, blame)``.

    ``inside``: the unknowns of an internal force strictly inside every cone, or None;
    ``normal_det``: whether the squeezes reach every pattern of normal forces (so no
    wrench needs pulling); ``rays``: the row's ``A`` with unlimited friction (the
    cones' first rows), for the pulling test.
    """
    d = len(c)
    x, r, z = None, -1.0, None
    if inside is not None:
        reach = max(
            (START_MARGIN + abs(b[m][0]) + math.hypot(b[m][1], b[m][2])) / depth for m, depth in enumerate(inside[1])
        )
        x = [reach * v for v in inside[0]]
    else:
        x, r, z = phase_one(A, b)
    if not r < 0:
        y = [_cone_value(A[m], b[m], x) for m in range(3)]
        blame = max(range(3), key=lambda m: math.hypot(y[m][1], y[m][2]) - y[m][0])
        if not normal_det and phase_one(rays, [[bm[0], 0.0, 0.0] for bm in b])[1] >= 0:
            blame = -1
        return [math.nan] * d, z, True, blame
    s, z = minimise(A, b, c, x, P)
    A, b, x, z = np.array(A), np.array(b), np.array(s), np.array(z)
    K, d = A.shape[0], A.shape[2]
    with np.errstate(all="ignore"):  # a zero pivot: the correction is not finite, z stays
        dual_polish(A, b, np.array(c), x, z, np.empty(K), np.empty((d, d + 1)), np.empty((K, 3)))
    return s, z.tolist(), False, -1
