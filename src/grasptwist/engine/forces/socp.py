r"""A batched primal-dual interior-point method for small second-order cone programs: many rows at once.

Each row is the problem

.. math:: \min_x\; c^T x \quad \text{s.t.} \quad y_m = A_m x + b_m \in Q^k = \{(t, z) : t \ge |z|\},\; m = 1 .. K

with ``x`` of a few numbers (the grip's squeezes, a soft contact's torsions, and phase I's
margin), and its dual ``max -sum_m b_m^T z_m`` s.t. ``sum_m A_m^T z_m = c``, ``z_m in Q^k``; the
duality gap is ``sum_m y_m . z_m``.  The cones have ``k`` components (a ray ``k = 1``, ``Q^3``,
``Q^4``); a smaller cone is padded with components that stay zero, and a half-space
``a^T x + h >= 0`` is the cone ``(a^T x + h, 0, 0)``.

Both phases start strictly inside the cones, primal and dual; phase II's dual start is
feasible too (phase I's leaves a residual in the dual equalities, which every step shrinks by
its length).  Each iteration is Mehrotra's predictor-corrector with
Nesterov-Todd scaling (the scaling point ``w`` with ``W z = W^{-1} y = lambda``, one per cone,
``W = beta (2 v v^T - J)``): an affine step ``lambda o v = -lambda o lambda``, the centring
weight ``sigma = (mu_aff / mu)^3``, then the corrected step, 0.99 of the way to the cones' edge
(in closed form per cone: :func:`_edge`).  The Newton system is the 3 x 3 (4 x 4)
``H dx = sum_m (W_m^{-1} A_m)^T W_m^{-1} v_m``, solved by elimination on arrays over the rows.
A row leaves once its gap is below ``GAP`` of its objective's scale (``1 + |c^T x|``): the
rows are scaled by their caller to order one, so the objective is then that close to the
optimum.  It takes 10-25 iterations a row, about a third of the Newton steps of a barrier
method with damped steps.

**Phase I** finds a strictly feasible point by minimising ``r`` with the cones widened to
``t_m + r >= |z_m|`` and ``r >= -1``, from ``x = 0`` and an ``r`` that makes the start
feasible, and a dual start that is feasible in ``r``'s column only (the residual of the
squeezes' columns shrinks step by step).  A row is decided once ``r <= -START_MARGIN``
(feasible, with room), its dual objective (a lower bound on ``r``, once the residual is
gone) is above 0 (infeasible: ``cannot-hold``), or its gap has closed (the sign of ``r``
decides).  An infeasible row whose cones share a boundary direction has ``r -> 0`` only
far along it: it stops at the cap with ``r > 0``.

Every array is components-first: cone vectors ``(k, K, n)`` (component, cone, row), ``A``
``(k, d, K, n)``, ``x`` ``(d, n)``.
"""

from __future__ import annotations

import contextlib

import numpy as np

__all__ = ["GAP", "START_MARGIN", "phase_one", "minimise", "dual_polish"]

#: A row stops once its duality gap is below this times ``1 + |c^T x|``.
GAP = 1e-10

#: Phase I stops a row whose every cone holds ``t - |z| >= START_MARGIN`` (of the row's scale).
START_MARGIN = 0.5

_RESIDUAL = 1e-9  # a dual residual below this (of the rows' order-one scale) counts as feasible
_ITERATIONS = 60  # a cap; rows need 10-25
_EDGE = 0.99  # the fraction of the way to the cones' edge a step goes


def _jdot(p, q):
    """``p^T J q`` per cone (``J = diag(1, -1, .., -1)``): ``(k, K, n)`` -> ``(K, n)``."""
    out = p[0] * q[0]
    for i in range(1, len(p)):
        out = out - p[i] * q[i]
    return out


def _dot(p, q):
    out = p[0] * q[0]
    for i in range(1, len(p)):
        out = out + p[i] * q[i]
    return out


def _norm_z(p):
    """``|z|`` of each cone's ``(t, z)``: ``(k, ...)`` -> ``(...)`` (0 for a ray, ``k = 1``)."""
    if len(p) == 1:
        return np.zeros_like(p[0])
    out = p[1] ** 2
    for i in range(2, len(p)):
        out = out + p[i] ** 2
    return np.sqrt(out)


def _jmul(u):
    """``J u``."""
    out = -u
    out[0] = u[0]
    return out


def _edge(x, d):
    """The largest ``alpha`` with ``x + alpha d`` in the cone (``inf``: none), ``(k, K, n)`` -> ``(n)``.

    ``1 / max(0, -lambda_min)`` with ``lambda_min = rho_0 - |rho_1|`` the smaller eigenvalue of
    ``d`` seen from ``x`` (``P(x^{-1/2}) d`` in the cone's Jordan algebra): with ``xi = x / s``,
    ``delta = d / s``, ``s = sqrt(x^T J x)``, ``rho_0 = xi^T J delta`` and ``rho_1 = delta_1 -
    (rho_0 + delta_0) / (xi_0 + 1) xi_1``.  No difference of near-equal squares, so a ray
    (``x_1 = d_1 = 0``, a half-space's cone) is stopped exactly at its apex.
    """
    s = np.sqrt(_jdot(x, x))
    xi, delta = x / s, d / s
    rho0 = _jdot(xi, delta)
    f = (rho0 + delta[0]) / (xi[0] + 1)
    t = _norm_z([delta[i] - f * xi[i] for i in range(len(x))]) - rho0
    with np.errstate(divide="ignore"):
        return np.where(t > 0, 1 / t, np.inf).min(axis=0)


def _spd_solve(h, g):
    """``h^-1 g`` for symmetric positive definite ``h`` (d x d nested lists of arrays over the rows) and
    ``g (d, n)``: elimination without pivoting."""
    d = len(g)
    h = [list(row) for row in h]
    g = list(g)
    for k in range(d):
        for i in range(k + 1, d):
            f = h[i][k] / h[k][k]
            for j in range(k + 1, d):
                h[i][j] = h[i][j] - f * h[k][j]
            g[i] = g[i] - f * g[k]
    x = [None] * d
    for i in reversed(range(d)):
        v = g[i]
        for j in range(i + 1, d):
            v = v - h[i][j] * x[j]
        x[i] = v / h[i][i]
    return np.stack(x)


def _apply(A, x):
    """``A x``: ``(k, d, K, n)``, ``(d, n)`` -> ``(k, K, n)``."""
    out = A[:, 0] * x[0]
    for j in range(1, len(x)):
        out += A[:, j] * x[j]
    return out


@np.errstate(divide="ignore", invalid="ignore")
def _iterate(A, b, c, x, z, leave):
    """Mehrotra steps on the rows of ``(A, b, c)`` from the strictly feasible primal ``x (d, n)`` and the
    dual ``z (k, K, n)`` inside the cones (in place), until ``leave(x, closed, dual)`` holds for a row or
    the cap.  The dual residual ``c - sum_m A_m^T z_m`` shrinks with every step, by the step's
    length; ``closed`` says the gap is below ``GAP`` of the objective, ``dual`` is the dual objective
    where that residual is below ``_RESIDUAL``, ``-inf`` elsewhere."""
    d = len(x)
    # A_m^T J A_m, once: the Newton matrix is sum_m (2 g_m g_m^T - A_m^T J A_m) / beta_m^2, g_m = A_m^T J w_m
    P = [[_jdot(A[:, i], A[:, j]) for j in range(d)] for i in range(d)]
    rows = np.arange(x.shape[1])
    K = A.shape[2]
    # the rows still iterating, gathered only when some leave (none do for the first 7 or so steps)
    a, bb, cc, xx, zz = A, b, c, x[:, rows], z[..., rows]
    for _ in range(_ITERATIONS):
        if not rows.size:
            break
        res = cc - np.stack([_dot(a[:, j], zz).sum(axis=0) for j in range(d)])
        y = bb + _apply(a, xx)
        # Nesterov-Todd scaling: W z = W^-1 y = lambda, W = beta (2 v v^T - J), w the scaling point
        ys, zs = np.sqrt(_jdot(y, y)), np.sqrt(_jdot(zz, zz))
        gamma = np.sqrt((1 + _dot(y, zz) / (ys * zs)) / 2)
        w = (y / ys + _jmul(zz) / zs) / (2 * gamma)
        v = w.copy()
        v[0] += 1
        v /= np.sqrt(2 * v[0])
        beta = np.sqrt(ys / zs)

        def w_inv(u, v=v, beta=beta):
            return _jmul(2 * v * _jdot(v, u) - u) / beta

        def w_mul(u, v=v, beta=beta):
            return beta * (2 * v * _dot(v, u) - _jmul(u))

        lam = w_mul(zz)
        g = [_jdot(a[:, j], w) for j in range(d)]
        scale = 1 / beta**2
        H = [[None] * d for _ in range(d)]
        for i in range(d):
            for j in range(i + 1):
                H[i][j] = H[j][i] = ((2 * g[i] * g[j] - P[i][j]) * scale).sum(axis=0)
        ridge = 1e-14 * np.max([H[i][i] for i in range(d)], axis=0)  # directions that move no cone
        for i in range(d):
            H[i][i] = H[i][i] + ridge

        def direction(rhs, lam=lam, a=a, H=H, w_inv=w_inv, res=res):
            # lambda o (W dz + W^-1 dy) = rhs, dy = A dx, sum_m A_m^T dz_m = res
            u0 = _jdot(lam, rhs) / _jdot(lam, lam)
            u = np.stack([u0] + [(rhs[i] - u0 * lam[i]) / lam[0] for i in range(1, len(lam))])
            wu = w_inv(u)
            dx = _spd_solve(H, [_dot(a[:, j], wu).sum(axis=0) - res[j] for j in range(d)])
            dy = _apply(a, dx)
            return dx, dy, w_inv(u - w_inv(dy))

        square = np.stack([_dot(lam, lam)] + [2 * lam[0] * lam[i] for i in range(1, len(lam))])
        mu = _dot(y, zz).sum(axis=0) / K
        dx, dy, dz = direction(-square)
        step = np.minimum(1.0, np.minimum(_edge(y, dy), _edge(zz, dz)))
        mu_aff = _dot(y + step * dy, zz + step * dz).sum(axis=0) / K
        sigma = np.clip(mu_aff / mu, 0, 1) ** 3
        p, q = w_inv(dy), w_mul(dz)
        rhs = -square - np.stack([_dot(p, q)] + [p[0] * q[i] + q[0] * p[i] for i in range(1, len(p))])
        rhs[0] += sigma * mu
        dx, dy, dz = direction(rhs)
        step = np.minimum(1.0, _EDGE * np.minimum(_edge(y, dy), _edge(zz, dz)))
        # a row whose step is not finite (round-off at the cones' edge) stops where it is, still inside
        good = np.isfinite(step) & np.isfinite(dx).all(axis=0) & np.isfinite(dz).all(axis=(0, 1))
        step = np.where(good, step, 0.0)
        xx = xx + step * np.where(good, dx, 0.0)
        zz = zz + step * np.where(good, dz, 0.0)
        x[:, rows], z[..., rows] = xx, zz
        gap = _dot(y + step * dy, zz).sum(axis=0)
        obj = (cc * xx).sum(axis=0)
        feasible = (np.abs(res) * (1 - step)).max(axis=0) <= _RESIDUAL
        stay = good & ~leave(xx, gap <= GAP * (1 + np.abs(obj)), np.where(feasible, obj - gap, -np.inf))
        if not stay.all():
            rows, a, bb, cc, xx, zz = rows[stay], a[..., stay], bb[..., stay], cc[:, stay], xx[:, stay], zz[..., stay]
            P = [[p[:, stay] for p in row] for row in P]
    return x


def _layout(A, b):
    """``(n, K, k, d)``, ``(n, K, k)`` -> components-first ``(k, d, K, n)``, ``(k, K, n)``."""
    return np.ascontiguousarray(A.transpose(2, 3, 1, 0)), np.ascontiguousarray(b.transpose(2, 1, 0))


def phase_one(A, b):
    """A strictly feasible ``x`` per row, the margin ``r`` reached (``r < 0``: feasible) and the dual.

    ``A (n, K, k, d)``, ``b (n, K, k)`` -> ``x (n, d)``, ``r (n)``, ``z (n, K, k)``.  With
    ``r < 0`` every cone holds ``t_m - |z_m| >= -r > 0`` at ``x``.  Where ``r > 0`` the cones'
    dual ``z_m`` (inside ``Q^k``, ``sum_m A_m^T z_m = 0`` to the residual) has
    ``-sum_m b_m . z_m > 0``: a proof that no ``x`` puts every ``A_m x + b_m`` in its cone
    (Farkas).
    """
    n, K, k, d = A.shape
    wide = np.zeros((n, K + 1, k, d + 1))
    wide[:, :K, :, :d] = A
    wide[:, :K, 0, d] = 1.0  # t_m + r
    wide[:, K, 0, d] = 1.0  # r + 1 >= 0
    bw = np.zeros((n, K + 1, k))
    bw[:, :K] = b
    bw[:, K, 0] = 1.0
    over = _norm_z(np.moveaxis(b, -1, 0)) - b[..., 0]
    x = np.zeros((d + 1, n))
    x[d] = np.maximum(over.max(axis=-1) + 1, 0.0)
    z = np.zeros((k, K + 1, n))
    z[0] = 0.25  # makes the r column of the dual, not yet the squeezes' columns
    c = np.zeros((d + 1, n))
    c[d] = 1.0
    wide, bw = _layout(wide, bw)

    def leave(x, closed, dual):
        # the dual bound is good to the residual times the squeezes
        return (x[d] <= -START_MARGIN) | (dual > _RESIDUAL * (1 + np.abs(x).sum(axis=0))) | (closed & (dual > -np.inf))

    x = _iterate(wide, bw, c, x, z, leave)
    return np.ascontiguousarray(x[:d].T), x[d], np.ascontiguousarray(z[:, :K].transpose(2, 1, 0))


def minimise(A, b, c, x):
    """The optimum from the strictly feasible ``x (n, d)``; returns ``x (n, d)`` and the dual ``z (n, K, k)``.

    ``A (n, K, k, d)``, ``b (n, K, k)``, ``c (n, d)`` with ``c = sum_m A_m^T e`` (``e = (1, 0,
    0)``: the objective is the sum of the cones' first components, as the grip's is), so
    ``z_m = e`` is a strictly feasible dual start.  The dual stays feasible
    (``sum_m A_m^T z_m = c`` to round-off); the gap ``sum_m y_m . z_m`` is below ``GAP``
    of the objective's scale where a row closed.
    """
    n = len(x)
    A, b = _layout(A, b)
    c = np.ascontiguousarray(c.T)
    x = np.ascontiguousarray(x.T)
    z = np.zeros((A.shape[0], A.shape[2], n))
    z[0] = 1.0

    def leave(x, closed, dual):
        return closed & (dual > -np.inf)

    x = _iterate(A, b, c, x, z, leave)
    return x.T, z.transpose(2, 1, 0)


def dual_polish(A, b, c, s, z):
    """``z`` moved to ``sum_m A_m^T z_m = c`` again (the solver keeps it to round-off of its large final steps).

    The correction ``dz_m = omega_m A_m delta`` with ``omega_m = |z_m| / |y_m|`` goes to the cones
    whose multipliers carry the optimum (``y_m`` on the edge, ``z_m`` large), not to idle ones
    (``z_m`` near 0), so every ``z_m`` stays in its cone to round-off.
    """
    y = np.einsum("nmkd,nd->nmk", A, s) + b
    res = c - np.einsum("nmkd,nmk->nd", A, z)
    omega = np.linalg.norm(z, axis=-1) / np.maximum(np.linalg.norm(y, axis=-1), 1e-300)
    h = np.einsum("nm,nmkd,nmke->nde", omega, A, A)
    with np.errstate(all="ignore"):
        delta = _solved(h + 1e-300 * np.eye(A.shape[-1]), res)
        dz = omega[..., None] * np.einsum("nmkd,nd->nmk", A, delta)
    return np.where(np.isfinite(dz).all(axis=(1, 2))[:, None, None], z + dz, z)


def _solved(h, res):
    """``h^-1 res`` row by row, NaN for a row whose ``h`` LAPACK finds exactly singular (every cone
    idle: nothing to polish there).  Which rows are exactly singular depends on the processor's
    kernel (OpenBLAS rounds differently), and one such row fails a batched solve whole.

    >>> _solved(np.array([[[2.0, 0], [0, 2]], [[0.0, 0], [0, 0]]]), np.ones((2, 2))).tolist()
    [[0.5, 0.5], [nan, nan]]
    """
    try:
        return np.linalg.solve(h, res[..., None])[..., 0]
    except np.linalg.LinAlgError:
        delta = np.full(res.shape, np.nan)
        for i in range(len(h)):
            with contextlib.suppress(np.linalg.LinAlgError):
                delta[i] = np.linalg.solve(h[i], res[i])
        return delta
